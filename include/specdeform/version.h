// The library's version: the release number (CMakeLists.txt's VERSION) at a release, else
// "<VERSION>+g<commit>" (cmake/version.cmake); what `specdeform --version` and
// specdeform.__version__ say.
#pragma once

#include <string_view>

namespace specdeform {

std::string_view version();

}  // namespace specdeform
