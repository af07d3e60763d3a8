// Reading a URDF file with Debian's urdfdom, with errors a person can act on.
//
// urdfdom reports problems through console_bridge, without line numbers. read_urdf() reads
// the file with tinyxml2 first (XML syntax errors carry tinyxml2's line), keeps where every
// <link> and <joint> element and its children start, captures urdfdom's messages, and throws
// crease::ConfigError naming the file, the line and the element (any error urdfdom logs is a
// refusal, also where it would go on without the broken part):
//   crease_robot.urdf:68: joint 'r_S2' <origin>: Unable to parse component [0.1x7] to a double ...
// Non-RT; one read at a time process-wide (console_bridge's handler is global).
#pragma once

#include <urdf_model/model.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace crease::robot {

// Where the elements of a URDF file are, for messages about them.
class UrdfSource {
 public:
  // One child element of a <link> or <joint> (any depth), e.g. <origin xyz="...">.
  struct Child {
    std::string tag;
    int line = 0;
    std::vector<std::string> attribute_values;
  };
  struct Element {
    std::string kind;  // "link" or "joint"
    std::string name;
    int line = 0;
    std::vector<Child> children;
  };

  UrdfSource() = default;
  UrdfSource(std::string file, std::vector<Element> elements)
      : file_(std::move(file)), elements_(std::move(elements)) {}

  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  // Every <link> and <joint> directly under <robot>, in file order.
  [[nodiscard]] const std::vector<Element>& elements() const noexcept { return elements_; }
  // The element of that kind and name, or nullptr.
  [[nodiscard]] const Element* find(std::string_view kind, std::string_view name) const noexcept;
  // "FILE:LINE: KIND 'NAME'" ("FILE: KIND 'NAME'" when the element is not in the file).
  [[nodiscard]] std::string where(std::string_view kind, std::string_view name) const;
  // Throws crease::ConfigError "where(kind, name): reason".
  [[noreturn]] void fail(std::string_view kind, std::string_view name, const std::string& reason) const;
  // The same, at the INDEX-th (0-based) <TAG> inside the element: "FILE:LINE: KIND 'NAME' <TAG>: reason".
  [[noreturn]] void fail_at_child(std::string_view kind, std::string_view name, std::string_view tag,
                                  int index, const std::string& reason) const;

 private:
  std::string file_;
  std::vector<Element> elements_;
};

struct UrdfDocument {
  std::shared_ptr<urdf::ModelInterface> model;  // never null
  UrdfSource source;
};

// Reads and parses PATH. Throws crease::ConfigError on an unreadable file, bad XML, or
// anything urdfdom refuses (a missing tag, a bad number, an unknown link...).
[[nodiscard]] UrdfDocument read_urdf(const std::string& path);

// The same for URDF text held in memory; FILE names it in messages.
[[nodiscard]] UrdfDocument read_urdf_text(const std::string& text, const std::string& file);

}  // namespace crease::robot
