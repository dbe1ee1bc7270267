#pragma once
// The example EDS files dnbridge ships (deploy/eds), as tests read them.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::test {

inline constexpr const char* kIoBlockEds = "dnbridge-example-io-block.eds";
inline constexpr const char* kValveManifoldEds = "dnbridge-example-valve-manifold.eds";

// The text of deploy/eds/`name`.
inline std::string example_eds_text(const std::string& name) {
  std::ifstream in(std::string(DNBRIDGE_EDS_DIR) + "/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// deploy/eds/`name` read; a test failure (and an empty file) if it does not read.
inline profiles::eds::EdsFile example_eds(const std::string& name) {
  auto parsed = profiles::eds::parse(example_eds_text(name));
  EXPECT_TRUE(parsed.file.has_value()) << name << " does not read";
  return parsed.file.value_or(profiles::eds::EdsFile{});
}

}  // namespace dnbridge::test
