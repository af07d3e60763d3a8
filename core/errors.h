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

// Bad user input: configuration, parameters, calibration and layout files, requests.
// The message names the file, line and field (or the request) and the reason.
class ConfigError : public Error {
 public:
  using Error::Error;
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
