// One loaded plugin library (dlopen), refused with a LoadError naming the file and the reason
// when it lies outside the plugin directories, when it or its directory is writable by group or
// others, when it cannot be loaded, has no entry point, or speaks another ABI. Non-RT.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/abi.h"

namespace crease {

class PluginLibrary {
 public:
  // Resolves `library` against `plugin_dirs`: a bare name "x" is looked up as "libx.so" then
  // "x.so" in each directory in order; a path (containing '/') must resolve inside one of them.
  static std::shared_ptr<PluginLibrary> open(const std::string& library, const std::vector<std::filesystem::path>& plugin_dirs);

  ~PluginLibrary();  // dlclose
  PluginLibrary(const PluginLibrary&) = delete;
  PluginLibrary& operator=(const PluginLibrary&) = delete;

  [[nodiscard]] const crease_plugin_descriptor& descriptor() const noexcept { return *descriptor_; }
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }
  [[nodiscard]] const std::string& plugin_name() const noexcept { return name_; }      // copied from the library
  [[nodiscard]] const std::string& plugin_version() const noexcept { return version_; }

 private:
  PluginLibrary() = default;
  void* handle_ = nullptr;
  const crease_plugin_descriptor* descriptor_ = nullptr;
  std::filesystem::path path_;
  std::string name_;
  std::string version_;
};

// The canonical forms of the configured plugin directories; refuses missing ones and ones
// writable by group or others (LoadError naming the directory).
std::vector<std::filesystem::path> canonical_plugin_dirs(const std::vector<std::filesystem::path>& dirs);

}  // namespace crease
