// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/version.h"

namespace scree {

const char* getVersionString() { return SCREE_VERSION_STRING; }

const char* getConfigurationString() {
  return "Scree " SCREE_VERSION_STRING " ("
#ifdef NDEBUG
         "optimised"
#else
         "debug"
#endif
#ifdef SCREE_WITH_OPENMP
         "; OpenMP on"
#else
         "; OpenMP off"
#endif
#ifdef SCREE_WITH_SUITESPARSE
         "; SuiteSparse on"
#else
         "; SuiteSparse off"
#endif
#ifdef SCREE_ENABLE_ASSERTS
         "; asserts on"
#else
         "; asserts off"
#endif
         ")";
}

}  // namespace scree
