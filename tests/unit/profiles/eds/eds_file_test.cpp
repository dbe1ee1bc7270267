// EDS files: the two examples under deploy/eds as they ship, the format's
// details (comments, entries over several lines, strings side by side, empty
// fields, case), and malformed files, each problem on its line.
#include "bridge/profiles/eds/eds_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <ostream>
#include <string>

#include "tests/support/example_eds.hpp"

namespace dnbridge::profiles::eds {
namespace {

using ::testing::HasSubstr;

using test::example_eds_text;

std::string all(const Parsed& parsed) {
  std::string out;
  for (const auto& p : parsed.problems) out += format_problem("t.eds", p) + "\n";
  return out;
}

cip::EPath assembly_data(std::uint32_t instance) {
  return cip::EPath{4, instance, std::nullopt, 3};
}

// A minimal valid file; `extra` is appended.
std::string minimal(const std::string& extra = {}) {
  return "[Device]\n"
         "VendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n" +
         extra;
}

TEST(EdsFile, TheIoBlockExampleReadsAsItShips) {
  const Parsed parsed = parse(example_eds_text("dnbridge-example-io-block.eds"));
  ASSERT_TRUE(parsed.file.has_value()) << all(parsed);
  EXPECT_TRUE(parsed.problems.empty()) << all(parsed);
  const EdsFile& f = *parsed.file;
  EXPECT_EQ(f.device.vendor_code, 65001);
  EXPECT_EQ(f.device.product_type, 7);
  EXPECT_EQ(f.device.product_code, 1);
  EXPECT_EQ(f.device.major_revision, 1);
  EXPECT_EQ(f.device.minor_revision, 3);
  EXPECT_EQ(f.device.product_name, "Example IO block 8DI/8DO/1AI");

  EXPECT_EQ(f.io.defaults, ConnectionKinds{0x01});
  ASSERT_EQ(f.io.connections.size(), 3u);
  for (ConnectionKind k :
       {ConnectionKind::kPoll, ConnectionKind::kChangeOfState, ConnectionKind::kCyclic}) {
    const ConnectionInfo* c = f.io.connection(k);
    ASSERT_NE(c, nullptr) << to_string(k);
    EXPECT_EQ(c->input, 1u);
    EXPECT_EQ(c->output, 1u);
  }
  EXPECT_EQ(f.io.connection(ConnectionKind::kStrobe), nullptr);
  const IoData* in = f.io.input(1);
  ASSERT_NE(in, nullptr);
  EXPECT_EQ(in->size, 4);
  EXPECT_EQ(in->name, "Inputs and status");
  EXPECT_EQ(in->path, assembly_data(100));
  EXPECT_EQ(to_string(in->carried_by), "poll, change of state, cyclic");
  ASSERT_NE(f.io.output(1), nullptr);
  EXPECT_EQ(f.io.output(1)->size, 2);

  ASSERT_EQ(f.params.size(), 9u);
  const Param* idle = f.param("Output idle value");
  ASSERT_NE(idle, nullptr);
  EXPECT_EQ(idle->number, 9u);
  EXPECT_EQ(idle->type.name, "BYTE");
  EXPECT_FALSE(idle->read_only());
  const Param* ai = f.param("analog input 1");
  ASSERT_NE(ai, nullptr);
  EXPECT_EQ(ai->number, 2u);
  EXPECT_EQ(ai->type.name, "INT");
  EXPECT_EQ(ai->units, "mV");
  EXPECT_EQ(ai->minimum, -10000.0);
  EXPECT_EQ(ai->maximum, 10000.0);
  EXPECT_TRUE(ai->read_only());
  EXPECT_EQ(ai->link, (cip::EPath{0x0F, 2, std::nullopt, 1}));
  EXPECT_FALSE(f.param(1)->read_only());
  EXPECT_EQ(f.param(1)->default_value, 3.0);

  const Assembly* a = f.assembly_at(in->path);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->number, 100u);
  EXPECT_EQ(a->size_bits(), 32u);
  ASSERT_EQ(a->members.size(), 3u);
  EXPECT_EQ(a->members[0].kind, Member::Kind::kParam);
  EXPECT_EQ(a->members[0].number, 3u);
  EXPECT_EQ(a->members[1].kind, Member::Kind::kParam);
  EXPECT_EQ(a->members[1].number, 5u);
  EXPECT_EQ(a->members[2].bits, 16);
  const Assembly* out = f.assembly_at(f.io.output(1)->path);
  ASSERT_NE(out, nullptr);
  ASSERT_EQ(out->members.size(), 2u);
  EXPECT_EQ(out->members[1].kind, Member::Kind::kPadding);
  EXPECT_EQ(out->members[1].bits, 8);
}

TEST(EdsFile, TheValveManifoldExampleReadsAsItShips) {
  const Parsed parsed = parse(example_eds_text("dnbridge-example-valve-manifold.eds"));
  ASSERT_TRUE(parsed.file.has_value()) << all(parsed);
  EXPECT_TRUE(parsed.problems.empty()) << all(parsed);
  const EdsFile& f = *parsed.file;
  EXPECT_EQ(f.device.product_code, 2);
  const ConnectionInfo* strobe = f.io.connection(ConnectionKind::kStrobe);
  ASSERT_NE(strobe, nullptr);
  EXPECT_EQ(strobe->input, 2u);
  EXPECT_EQ(strobe->output, 0u);  // a strobe consumes no output
  EXPECT_EQ(f.io.input(2)->size, 1);
  EXPECT_EQ(f.io.connection(ConnectionKind::kChangeOfState), nullptr);
  ASSERT_EQ(f.assemblies.size(), 3u);
  ASSERT_EQ(f.assemblies[1].members.size(), 3u);  // two 1-bit members and 6 bits of padding
  EXPECT_EQ(f.assemblies[1].members[0].kind, Member::Kind::kPath);
  EXPECT_EQ(f.assemblies[1].members[0].path, (cip::EPath{0x08, 1, std::nullopt, 3}));
  EXPECT_EQ(f.assemblies[1].members[2].kind, Member::Kind::kPadding);
  EXPECT_EQ(f.param("Low pressure limit")->default_value, 400.0);
}

TEST(EdsText, CommentsContinuationStringsAndEmptyFieldsAreRead) {
  const Lexed lexed =
      lex("$ a comment [not a section]\n"
          "[ Section One ]   $ comment after a header\n"
          "  key = 1,\n"
          "        \"two $ not a comment\" \"joined\",   $ a comment inside an entry\n"
          "        , \"say \\\"hi\\\"\", bare text ;\n"
          "KEY2=;\n"
          "[other]\n"
          "x = 0x1F;\n");
  ASSERT_TRUE(lexed.problems.empty()) << lexed.problems.front().message;
  ASSERT_EQ(lexed.text.sections.size(), 2u);
  const Section* s = lexed.text.find("section one");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->line, 2u);
  const Entry* key = s->find("KEY");
  ASSERT_NE(key, nullptr);
  EXPECT_EQ(key->line, 3u);
  ASSERT_EQ(key->fields.size(), 5u);
  EXPECT_EQ(key->fields[0].text, "1");
  EXPECT_EQ(key->fields[1].text,
            "two $ not a comment"
            "joined");
  EXPECT_TRUE(key->fields[1].quoted);
  EXPECT_EQ(key->fields[1].line, 4u);
  EXPECT_TRUE(key->fields[2].empty());
  EXPECT_EQ(key->fields[3].text, "say \"hi\"");
  EXPECT_EQ(key->fields[4].text, "bare text");
  const Entry* key2 = s->find("key2");
  ASSERT_NE(key2, nullptr);
  ASSERT_EQ(key2->fields.size(), 1u);
  EXPECT_TRUE(key2->fields[0].empty());
}

TEST(EdsFile, UnknownSectionsAndKeywordsAreIgnored) {
  const Parsed parsed = parse(minimal(
      "[Vendor Stuff]\nWhatever = \"x\", 1;\n[Device Classification]\nClass1 = DeviceNet;\n"));
  ASSERT_TRUE(parsed.file.has_value()) << all(parsed);
  EXPECT_TRUE(parsed.problems.empty()) << all(parsed);
  EXPECT_TRUE(parsed.file->io.connections.empty());
}

struct Malformed {
  const char* what;
  std::string text;
  std::uint32_t line;
  const char* says;
};

void PrintTo(const Malformed& m, std::ostream* os) { *os << m.what; }

// The case's name, for the test's: letters and digits of `what`.
std::string case_name(const ::testing::TestParamInfo<Malformed>& info) {
  std::string name;
  bool upper = true;
  for (const char* c = info.param.what; *c; ++c) {
    if (std::isalnum(static_cast<unsigned char>(*c))) {
      name += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(*c))) : *c;
      upper = false;
    } else {
      upper = true;
    }
  }
  return name;
}

class EdsMalformed : public ::testing::TestWithParam<Malformed> {};

TEST_P(EdsMalformed, IsAnErrorOnItsLine) {
  const Malformed& m = GetParam();
  const Parsed parsed = parse(m.text);
  EXPECT_FALSE(parsed.file.has_value()) << m.what;
  bool found = false;
  for (const auto& p : parsed.problems) {
    if (p.severity == Problem::Severity::kError && p.line == m.line &&
        p.message.find(m.says) != std::string::npos) {
      found = true;
    }
  }
  EXPECT_TRUE(found) << m.what << ": expected an error on line " << m.line << " saying \"" << m.says
                     << "\", got:\n"
                     << all(parsed);
}

const std::string kIo =
    "[IO_Info]\n"                                                          // line 3
    "Default = 0x0001;\n"                                                  // 4
    "PollInfo = 0x0001, 1, 1;\n"                                           // 5
    "Input1 = 4, 0, 0x0001, \"in\", 6, \"20 04 24 64 30 03\", \"\";\n"     // 6
    "Output1 = 2, 0, 0x0001, \"out\", 6, \"20 04 24 96 30 03\", \"\";\n";  // 7

INSTANTIATE_TEST_SUITE_P(
    Each, EdsMalformed,
    ::testing::Values(
        Malformed{"no Device section", "[File]\nDescText = \"x\";\n", 1, "no [Device] section"},
        Malformed{"a required key missing", "[Device]\nVendCode = 1; ProdType = 0;\n", 1,
                  "[Device] has no ProdCode"},
        Malformed{"a string not closed", minimal("[File]\nDescText = \"open\n;\n"), 4,
                  "a string not closed on its line"},
        Malformed{"an entry not ended", minimal("[File]\nDescText = \"x\"\n[IO_Info]\n"), 4,
                  "entry DescText is not ended by ';'"},
        Malformed{"a header not closed", minimal("[IO_Info\nDefault = 1;\n"), 3,
                  "without its closing ']'"},
        Malformed{"an entry before any section", "VendCode = 1;\n" + minimal(), 1,
                  "entry VendCode is not in a section"},
        Malformed{"a line that is not an entry", minimal("[File]\njust words\n;\n"), 4,
                  "is not an entry"},
        Malformed{"a path size that is wrong",
                  minimal("[IO_Info]\nInput1 = 4, 0, 1, \"in\", 4, \"20 04 24 64 30 03\", \"\";\n"),
                  4, "path has 6 bytes, its size field says 4"},
        Malformed{"a path that is not hex",
                  minimal("[IO_Info]\nInput1 = 4, 0, 1, \"in\", 6, \"20 04 24 6G 30 03\", \"\";\n"),
                  4, "is not hex bytes"},
        Malformed{"a poll naming an input that is not there",
                  minimal("[IO_Info]\nPollInfo = 1, 3, 0;\n"), 4, "Input3 is not in [IO_Info]"},
        Malformed{"a default without its connection",
                  minimal("[IO_Info]\nDefault = 0x0005;\nPollInfo = 0x0001, 0, 0;\n"), 4,
                  "Default names change of state, which no COSInfo entry describes"},
        Malformed{"an input twice", minimal(kIo + "Input1 = 1, 0, 1, \"x\", 0, \"\", \"\";\n"), 8,
                  "Input1 is given twice"},
        Malformed{"a parameter whose size is not its type's",
                  minimal("[Params]\nParam1 = 0, 0, , 0, 0xC7, 4, \"speed\", \"\", \"\", 0, 10, "
                          "1, 1, 1, 1, 0, , , , , 0;\n"),
                  4, "data size 4 is not that of UINT (2)"},
        Malformed{"a default given twice",
                  minimal("[IO_Info]\nDefault = 0x0001;\nPollInfo = 1, 0, 0;\nDefault = 1;\n"), 6,
                  "Default is given twice"},
        Malformed{"a default outside the limits",
                  minimal("[Params]\nParam1 = 0, 0, , 0, 0xC6, 1, \"x\", \"\", \"\", 0, 10, "
                          "11;\n"),
                  4, "default 11 is outside 0..10"},
        Malformed{"a limit the type cannot hold",
                  minimal("[Params]\nParam1 = 0, 0, , 0, 0xC6, 1, \"x\", \"\", \"\", 0, 300, "
                          "1;\n"),
                  4, "maximum 300 is not a USINT value"},
        Malformed{"assembly members that do not add up",
                  minimal("[Assembly]\nAssem100 = \"in\", \"20 04 24 64 30 03\", 32, 0, , , "
                          "8, , 16, ;\n"),
                  4, "its members take 24 bits, its size is 32"},
        Malformed{"an input whose assembly is of another size",
                  minimal(kIo + "[Assembly]\nAssem100 = \"in\", \"20 04 24 64 30 03\", 16, 0;\n"),
                  6, "is 4 bytes, the Assem100 it names is 16 bits"},
        Malformed{"a member naming a parameter that is not there",
                  minimal("[Assembly]\nAssem1 = \"a\", , 8, 0, , , 8, Param9;\n"), 4,
                  "member Param9 is not in [Params]"},
        Malformed{"an assembly that contains itself",
                  minimal("[Assembly]\nAssem1 = \"a\", , 8, 0, , , 8, Assem2;\n"
                          "Assem2 = \"b\", , 8, 0, , , 8, Assem1;\n"),
                  4, "Assem1 (a) contains itself through its members"},
        Malformed{"a REAL limit no REAL holds",
                  minimal("[Params]\nParam1 = 0, 0, , 0, 0xCA, 4, \"x\", \"\", \"\", 0, 1e39, "
                          "0;\n"),
                  4, "maximum 1e+39 is not a REAL value"},
        Malformed{"an 8-byte limit one past the type",
                  minimal("[Params]\nParam1 = 0, 0, , 0, 0xC9, 8, \"x\", \"\", \"\", 0, "
                          "18446744073709551615, 0;\n"),
                  4, "is not a ULINT value"},
        Malformed{"a member that is not a reference",
                  minimal("[Assembly]\nAssem1 = \"a\", , 8, 0, , , 8, Widget;\n"), 4,
                  "member 1 \"Widget\" is neither a path, ParamN nor AssemN"}),
    case_name);

TEST(EdsFile, AStringLeftOpenIsOneErrorAndItsEntryGoesOn) {
  const Parsed parsed = parse(minimal("[File]\nDescText = \"open\n  ;\nRevision = 1.0;\n"));
  EXPECT_EQ(parsed.errors, 1u) << all(parsed);
  EXPECT_FALSE(parsed.file.has_value());
}

TEST(EdsFile, ANumberThatIsNotOneIsAnErrorOnItsLine) {
  const Parsed parsed = parse(
      "[Device]\nVendCode = 12x;\nProdType = 99999999999999999999;"
      " ProdCode = 1;\nMajRev = 1; MinRev = 300;\n");
  EXPECT_FALSE(parsed.file.has_value());
  const std::string text = all(parsed);
  EXPECT_THAT(text, HasSubstr("t.eds:2: error: VendCode: value \"12x\" is not a number"));
  EXPECT_THAT(text, HasSubstr("t.eds:4: error: MinRev: value 300 is out of range (0..255)"));
  EXPECT_THAT(text, HasSubstr("t.eds:3: error: ProdType: value 99999999999999999999 is out of "
                              "range (0..65535)"));
}

TEST(EdsFile, EveryProblemIsReportedInOnePassInLineOrder) {
  const Parsed parsed = parse(
      "[Device]\nVendCode = x;\nProdType = 0; ProdCode = 1; MajRev = 1;"
      " MinRev = 1;\n[IO_Info]\nPollInfo = 1, 2, 0;\nInput1 = \"x;\n");
  EXPECT_FALSE(parsed.file.has_value());
  ASSERT_GE(parsed.problems.size(), 3u) << all(parsed);
  for (std::size_t i = 1; i < parsed.problems.size(); ++i) {
    EXPECT_LE(parsed.problems[i - 1].line, parsed.problems[i].line) << all(parsed);
  }
}

TEST(EdsFile, AParameterOfATypeNotReadIsLeftOutWithAWarning) {
  const Parsed parsed =
      parse(minimal("[Params]\nParam1 = 0, 0, , 0, 0xDB, 4, \"when\";\n"
                    "[Assembly]\nAssem1 = \"a\", , 32, 0, , , 32, Param1;\n"));
  ASSERT_TRUE(parsed.file.has_value()) << all(parsed);
  EXPECT_TRUE(parsed.file->params.empty());
  // The assembly still names it; the file says it was left out.
  EXPECT_EQ(parsed.file->params_left_out, std::vector<unsigned>{1});
  EXPECT_TRUE(parsed.file->param_left_out(1));
  EXPECT_FALSE(parsed.file->param_left_out(2));
  ASSERT_EQ(parsed.problems.size(), 1u) << all(parsed);
  EXPECT_EQ(parsed.problems[0].severity, Problem::Severity::kWarning);
  EXPECT_EQ(parsed.problems[0].line, 4u);
  EXPECT_THAT(parsed.problems[0].message, HasSubstr("data type 0xDB is not one dnbridge reads"));
}

TEST(EdsFile, WhatRefersToAnEntryFoundWrongSaysNothingMore) {
  const Parsed parsed = parse(minimal(
      "[IO_Info]\nPollInfo = 1, 1, 0;\nInput1 = 4, 0, 1, \"in\", 6, \"20 04 zz\", \"\";\n"));
  EXPECT_FALSE(parsed.file.has_value());
  ASSERT_EQ(parsed.problems.size(), 1u) << all(parsed);
  EXPECT_EQ(parsed.problems[0].line, 5u);
  // Nor what refers to a parameter written another way, or to a failed PollInfo.
  const Parsed param =
      parse(minimal("[IO_Info]\nDefault = 1;\nPollInfo = x, 0, 0;\n[Params]\n"
                    "Param05 = 0, 0, , 0, 0xC6, 9, \"p\";\n[Assembly]\n"
                    "Assem1 = \"a\", , 8, 0, , , 8, Param5;\n"));
  EXPECT_EQ(param.errors, 2u) << all(param);  // PollInfo's field, Param05's size
}

TEST(EdsFile, AParameterGivenTwiceIsAnErrorEvenWhenTheFirstWasLeftOut) {
  const Parsed parsed =
      parse(minimal("[Params]\nParam1 = 0, 0, , 0, 0xDB, 4, \"when\";\n"
                    "Param1 = 0, 0, , 0, 0xC6, 1, \"again\";\n"));
  EXPECT_THAT(all(parsed), HasSubstr("t.eds:5: error: Param1 is given twice"));
}

TEST(EdsFile, AnAssemblyGivenTwiceIsAnErrorEvenWhenTheFirstWasLeftOut) {
  const Parsed parsed =
      parse(minimal("[Assembly]\nAssem1 = \"a\", , 99999999;\n"
                    "Assem1 = \"b\", , 8, 0, , , 8, ;\n"));
  EXPECT_THAT(all(parsed), HasSubstr("t.eds:4: error: Assem1: size in bits 99999999"));
  EXPECT_THAT(all(parsed), HasSubstr("t.eds:5: error: Assem1 is given twice"));
  EXPECT_FALSE(parsed.file.has_value());
}

TEST(EdsFile, AnErrorPastTheProblemsShownStillMakesTheFileUnusable) {
  std::string text = minimal("[IO_Info]\n");
  for (int i = 0; i < 60; ++i)
    text += "Input" + std::to_string(i + 1) + " = 1, 0, 0x10, \"\", 0, , \"\";\n";
  text += "PollInfo = 1, 99, 0;\n";
  const Parsed parsed = parse(text);
  EXPECT_FALSE(parsed.file.has_value());
  EXPECT_EQ(parsed.problems.size(), kMaxProblems);
  EXPECT_EQ(parsed.errors, 1u);
  EXPECT_EQ(parsed.not_shown, 11u);
  // The error is among those shown, warnings making up the rest.
  EXPECT_EQ(std::count_if(parsed.problems.begin(), parsed.problems.end(),
                          [](const Problem& p) { return p.severity == Problem::Severity::kError; }),
            1);
}

TEST(EdsFile, AByteOrderMarkDuplicateSectionsAndALostHeaderAreHandled) {
  const Parsed parsed =
      parse("\xEF\xBB\xBF" + minimal("[Device]\nVendCode = 9;\n[Params\nParam1 = x;\n"));
  EXPECT_FALSE(parsed.file.has_value());
  const std::string text = all(parsed);
  EXPECT_THAT(text, HasSubstr("t.eds:3: warning: [Device] is given again"));
  EXPECT_THAT(text, HasSubstr("t.eds:5: error: a section header without its closing ']'"));
  EXPECT_EQ(parsed.errors, 1u) << text;  // nothing about the entry in the lost section
}

TEST(EdsFile, AProblemIsWrittenAsCompilersWriteThem) {
  EXPECT_EQ(format_problem("dir/a.eds", {7, Problem::Severity::kError, "bad"}),
            "dir/a.eds:7: error: bad");
  EXPECT_EQ(format_problem("a.eds", {1, Problem::Severity::kWarning, "odd"}),
            "a.eds:1: warning: odd");
}

}  // namespace
}  // namespace dnbridge::profiles::eds
