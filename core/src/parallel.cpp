// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/parallel.h"

#ifdef SCREE_WITH_OPENMP
#include <omp.h>
#endif

namespace scree {

#ifdef SCREE_WITH_OPENMP
void setNumThreads(int n) { omp_set_num_threads(n >= 1 ? n : omp_get_num_procs()); }
int getNumThreads() { return omp_get_max_threads(); }
#else
void setNumThreads(int) {}
int getNumThreads() { return 1; }
#endif

}  // namespace scree
