// Test helpers: the shipped robot files, edited copies of them in a per-process temporary folder,
// and the line numbers of text in them (the URDF errors must name them).
#pragma once

#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace robot_files {

inline std::string shipped(const std::string& name) {
  return std::string(CREASE_SOURCE_DIR) + "/config/robot/" + name;
}

inline std::string read(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::string tmp_dir() {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("crease_robot_model_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

// Writes TEXT to NAME in the temporary folder; returns its path.
inline std::string write(const std::string& name, const std::string& text) {
  const std::string path = tmp_dir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// TEXT with the first FROM after the first AFTER replaced by TO (both must be there).
inline std::string replace(std::string text, const std::string& from, const std::string& to,
                           const std::string& after = "") {
  const std::size_t start = after.empty() ? 0 : text.find(after);
  REQUIRE(start != std::string::npos);
  const std::size_t at = text.find(from, start);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

// TEXT without the line holding the first NEEDLE after the first AFTER.
inline std::string remove_line(std::string text, const std::string& needle, const std::string& after) {
  const std::size_t start = text.find(after);
  REQUIRE(start != std::string::npos);
  const std::size_t at = text.find(needle, start);
  REQUIRE(at != std::string::npos);
  const std::size_t begin = text.rfind('\n', at) + 1;
  return text.erase(begin, text.find('\n', at) + 1 - begin);
}

// The 1-based line of the first NEEDLE after the first AFTER.
inline int line_of(const std::string& text, const std::string& needle, const std::string& after = "") {
  const std::size_t start = after.empty() ? 0 : text.find(after);
  REQUIRE(start != std::string::npos);
  const std::size_t at = text.find(needle, start);
  REQUIRE(at != std::string::npos);
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n';
  return line;
}

// The shipped YAML, edited, beside a URDF named URDF_NAME written with URDF_TEXT.
inline std::string write_robot(const std::string& yaml_text, const std::string& urdf_name,
                               const std::string& urdf_text) {
  write(urdf_name, urdf_text);
  const std::string yaml = replace(yaml_text, "urdf: crease_robot.urdf", "urdf: " + urdf_name);
  return write(urdf_name + ".yaml", yaml);
}

}  // namespace robot_files
