// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// SCREE_ASSERT (cheap invariants, compiled in with SCREE_ENABLE_ASSERTS) and SCREE_VALIDATE (heavy consistency
// checks, compiled in with SCREE_VALIDATE). A failed check calls the installed handler; the default handler
// logs the message at ERROR level and aborts.
#pragma once

#include <functional>

namespace scree {
using AssertHandler = std::function<void(const char* expression, const char* file, int line)>;
/// Replace the handler (an empty function restores the default). Returns the previous one.
AssertHandler setAssertHandler(AssertHandler handler);
namespace detail {
void assertFailed(const char* expression, const char* file, int line);
}
}  // namespace scree

#ifdef SCREE_ENABLE_ASSERTS
#define SCREE_ASSERT(expr) ((expr) ? void(0) : ::scree::detail::assertFailed(#expr, __FILE__, __LINE__))
#else
#define SCREE_ASSERT(expr) void(0)
#endif

#ifdef SCREE_VALIDATE
#define SCREE_VALIDATE_CHECK(expr) ((expr) ? void(0) : ::scree::detail::assertFailed(#expr, __FILE__, __LINE__))
#else
#define SCREE_VALIDATE_CHECK(expr) void(0)
#endif
