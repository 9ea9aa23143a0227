// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/assert.h"

#include <cstdlib>
#include <mutex>
#include <string>

#include "scree/core/logger.h"

namespace scree {
namespace {
std::mutex& handlerMutex() {
  static std::mutex m;
  return m;
}
AssertHandler& handler() {
  static AssertHandler h;
  return h;
}
}  // namespace

AssertHandler setAssertHandler(AssertHandler h) {
  std::lock_guard<std::mutex> lock(handlerMutex());
  AssertHandler old = std::move(handler());
  handler() = std::move(h);
  return old;
}

namespace detail {
void assertFailed(const char* expression, const char* file, int line) {
  AssertHandler h;
  {
    std::lock_guard<std::mutex> lock(handlerMutex());
    h = handler();
  }
  if (h) {
    h(expression, file, line);
    return;
  }
  Logger::error(std::string("assertion failed: ") + expression + " at " + file + ":" + std::to_string(line));
  std::abort();
}
}  // namespace detail
}  // namespace scree
