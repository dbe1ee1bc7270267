# Writes a C++ source defining `std::string_view FUNCTION() noexcept` (in
# namespace NAMESPACE) that returns the bytes of INPUT, for files the program
# carries inside it. Run as a script:
#   cmake -DINPUT=file -DOUTPUT=file.cpp -DNAMESPACE=ns -DFUNCTION=name -P embed_text.cmake
file(READ "${INPUT}" hex HEX)
string(LENGTH "${hex}" hex_length)
math(EXPR size "${hex_length} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "'\\\\x\\1'," bytes "${hex}")
# A line every 16 bytes, for a readable file.
string(REPEAT "'[^']+'," 16 sixteen)
string(REGEX REPLACE "(${sixteen})" "\\1\n    " bytes "${bytes}")
file(WRITE "${OUTPUT}" "// Generated from ${INPUT} at build time: edit that file.
#include <string_view>

namespace ${NAMESPACE} {
namespace {
constexpr char kBytes[] = {
    ${bytes}};
}  // namespace

std::string_view ${FUNCTION}() noexcept { return {kBytes, ${size}}; }

}  // namespace ${NAMESPACE}
")
