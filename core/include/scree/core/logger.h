// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Project logger: levels and a replaceable sink. The default sink writes WARNING and above to stderr.
// Thread-safe: the sink is called under a mutex.
#pragma once

#include <functional>
#include <string>

namespace scree {

enum class LogLevel { DEBUG = 0, INFO = 1, WARNING = 2, ERROR = 3, OFF = 4 };

class Logger {
 public:
  using Sink = std::function<void(LogLevel, const std::string&)>;

  /// Replace the sink; an empty function restores the default (stderr).
  static void setSink(Sink sink);
  /// Messages below this level are dropped before formatting reaches the sink. Default WARNING.
  static void setLevel(LogLevel level);
  static LogLevel getLevel();

  static void log(LogLevel level, const std::string& message);
  static void debug(const std::string& m) { log(LogLevel::DEBUG, m); }
  static void info(const std::string& m) { log(LogLevel::INFO, m); }
  static void warning(const std::string& m) { log(LogLevel::WARNING, m); }
  static void error(const std::string& m) { log(LogLevel::ERROR, m); }

  /// Logs `message` at WARNING the first time `key` is seen in this process (for "once" warnings).
  static void warningOnce(const std::string& key, const std::string& message);
  /// Forgets the keys warningOnce has seen, so each of its warnings is logged once more (for tests that count
  /// them, and hosts that restart their simulations).
  static void resetWarningsOnce();
};

}  // namespace scree
