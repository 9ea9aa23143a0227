// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/logger.h"

#include <atomic>
#include <iostream>
#include <mutex>
#include <set>

namespace scree {
namespace {
struct LoggerState {
  std::mutex mutex;
  Logger::Sink sink;
  std::atomic<int> level{int(LogLevel::WARNING)};
  std::set<std::string> onceKeys;
};
LoggerState& state() {
  static LoggerState s;
  return s;
}
const char* levelName(LogLevel l) {
  switch (l) {
    case LogLevel::DEBUG: return "debug";
    case LogLevel::INFO: return "info";
    case LogLevel::WARNING: return "warning";
    case LogLevel::ERROR: return "error";
    default: return "";
  }
}
}  // namespace

void Logger::setSink(Sink sink) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().sink = std::move(sink);
}
void Logger::setLevel(LogLevel level) { state().level = int(level); }
LogLevel Logger::getLevel() { return LogLevel(state().level.load()); }

void Logger::log(LogLevel level, const std::string& message) {
  if (int(level) < state().level.load() || level == LogLevel::OFF) return;
  std::lock_guard<std::mutex> lock(state().mutex);
  if (state().sink) {
    state().sink(level, message);
  } else {
    std::cerr << "[scree " << levelName(level) << "] " << message << "\n";
  }
}

void Logger::warningOnce(const std::string& key, const std::string& message) {
  {
    std::lock_guard<std::mutex> lock(state().mutex);
    if (!state().onceKeys.insert(key).second) return;
  }
  warning(message);
}

void Logger::resetWarningsOnce() {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().onceKeys.clear();
}

}  // namespace scree
