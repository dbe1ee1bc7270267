// dnbctl eds check, the program: a usable file is described on stdout (exit
// 0), a file with errors has each one on stderr as FILE:LINE (exit 1), a file
// that cannot be read is a usage error (exit 2); --json says the same as one
// document.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "subprocess.hpp"

namespace dnbridge::dnbctl {
namespace {

using ::testing::HasSubstr;

const std::string kExample = std::string(DNBRIDGE_EDS_DIR) + "/dnbridge-example-io-block.eds";

TEST(DnbctlEds, AnExampleIsDescribed) {
  const auto r = testing::run(DNBCTL_PATH, {"eds", "check", kExample});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("device: vendor 65001 (dnbridge examples), product type 7"));
  EXPECT_THAT(r.out, HasSubstr("  poll (default): produces input 1 (4 bytes, \"Inputs and "
                               "status\", assembly 100), consumes output 1 (2 bytes"));
  EXPECT_THAT(r.out, HasSubstr("  150 \"Outputs\": 16 bits: 8 bits Param4 (Digital outputs), 8 "
                               "bits padding"));
  EXPECT_EQ(r.err, "");
}

TEST(DnbctlEds, AFileWithErrorsHasEachOnItsLineAndExits1) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("dnbctl-eds-" + std::to_string(::getpid()) + ".eds");
  {
    std::ofstream out(path);
    out << "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n"
           "[IO_Info]\nPollInfo = 1, 3, 0;\nInput1 = 4, 0, 1, \"in\", 6, \"20 04\", \"\";\n";
  }
  const auto r = testing::run(DNBCTL_PATH, {"eds", "check", path.string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr(path.string() + ":4: error: poll connection: Input3 is not in"));
  EXPECT_THAT(r.err, HasSubstr(path.string() + ":5: error: Input1: path has 2 bytes, its size "
                                               "field says 6"));
  EXPECT_THAT(r.err, HasSubstr("not usable, 2 errors"));
  EXPECT_EQ(r.out, "");

  const auto j = testing::run(DNBCTL_PATH, {"eds", "check", path.string(), "--json"});
  EXPECT_EQ(j.exit_code, 1);
  const auto doc = nlohmann::json::parse(j.out);
  EXPECT_EQ(doc["valid"], false);
  EXPECT_EQ(doc["errors"], 2);
  ASSERT_EQ(doc["problems"].size(), 2u);
  EXPECT_EQ(doc["problems"][0]["line"], 4);
  EXPECT_EQ(doc["problems"][0]["severity"], "error");
  std::filesystem::remove(path);
}

TEST(DnbctlEds, JsonDescribesAUsableFile) {
  const auto r = testing::run(DNBCTL_PATH, {"eds", "check", kExample, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  EXPECT_EQ(doc["valid"], true);
  EXPECT_EQ(doc["device"]["product_code"], 1);
  ASSERT_EQ(doc["connections"].size(), 3u);
  EXPECT_EQ(doc["connections"][0]["kind"], "poll");
  EXPECT_EQ(doc["connections"][0]["input_bytes"], 4);
  EXPECT_EQ(doc["parameters"].size(), 9u);
  EXPECT_EQ(doc["assemblies"][1]["members"][1], "8 bits padding");
}

TEST(DnbctlEds, AFileThatCannotBeReadIsAUsageError) {
  auto r = testing::run(DNBCTL_PATH, {"eds", "check", "/nonexistent/x.eds"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("cannot read /nonexistent/x.eds: No such file or directory"));
  r = testing::run(DNBCTL_PATH, {"eds", "check", DNBRIDGE_EDS_DIR});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("it is a directory"));
  r = testing::run(DNBCTL_PATH, {"eds"});
  EXPECT_EQ(r.exit_code, 2);
}

}  // namespace
}  // namespace dnbridge::dnbctl
