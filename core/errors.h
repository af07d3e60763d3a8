// Error types thrown at configure/load time only (never inside a loop's update).
#pragma once

#include <stdexcept>
#include <string>

namespace crease {

// Base of every Crease error a user can cause.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where a piece of user input came from. line/column are 1-based; 0 when unknown.
struct SourceLoc {
  std::string file;
  int line = 0;
  int column = 0;

  // "FILE:LINE:COLUMN"
  [[nodiscard]] std::string str() const {
    return file + ":" + std::to_string(line) + ":" + std::to_string(column);
  }
};

// Bad user input: configuration, parameters, calibration and layout files, requests.
// The message names the file, line and field (or the request) and the reason. The one
// configuration error of Crease: the daemon's configuration loader (core/config), plugin
// parameters (core/params.h) and the throw tier of core/assert.h all throw it.
class ConfigError : public Error {
 public:
  // A message that already says where and what (e.g. Params::where() + ": " + reason).
  explicit ConfigError(const std::string& message) : Error(message) {}
  // what() reads "FILE:LINE:COLUMN: KEY.PATH: reason"; the parts stay readable.
  ConfigError(SourceLoc loc, std::string key_path, std::string reason)
      : Error(loc.str() + ": " + key_path + ": " + reason),
        loc_(std::move(loc)),
        key_path_(std::move(key_path)),
        reason_(std::move(reason)) {}

  // Empty (line 0, no key) for an error built from a whole message.
  [[nodiscard]] const SourceLoc& loc() const noexcept { return loc_; }
  [[nodiscard]] const std::string& key_path() const noexcept { return key_path_; }
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }

 private:
  SourceLoc loc_;
  std::string key_path_;
  std::string reason_;
};

// A plugin library that the host refuses to load (path, permissions, entry point, ABI).
// The message names the file and the reason.
class LoadError : public Error {
 public:
  using Error::Error;
};

// A port binding that does not match the port's other end (type, version, size, kind, writer).
class PortError : public ConfigError {
 public:
  using ConfigError::ConfigError;
};

}  // namespace crease
