#pragma once
// An assembly's member list as a device reports it (Assembly attribute 2,
// cip/assembly.hpp) against what its EDS describes ([Assembly] AssemN): the
// differences, for a configuration fault that says what differs.
#include <string>
#include <vector>

#include "bridge/cip/assembly.hpp"
#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::profiles::eds {

// One sentence per difference, empty when they agree. A member is compared
// by its size in bits and by what it is: padding, or a path (a ParamN member
// by its parameter's link path; an AssemN member, or a ParamN without a link
// path, by its size only).
std::vector<std::string> member_differences(const EdsFile& file, const Assembly& expected,
                                            const std::vector<cip::AssemblyMember>& reported);

}  // namespace dnbridge::profiles::eds
