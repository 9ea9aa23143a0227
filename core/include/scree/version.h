// Version and the active build configuration as a runtime string.
#pragma once

namespace scree {
/// e.g. "Scree 0.1.0 (Release; OpenMP on; SuiteSparse on; asserts off)".
const char* getConfigurationString();
const char* getVersionString();
}  // namespace scree
