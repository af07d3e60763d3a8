#include "core/config/yaml_bounds.h"

#include <algorithm>
#include <sstream>
#include <unordered_map>
#include <vector>

#include <yaml-cpp/eventhandler.h>

#include "core/errors.h"

namespace crease::config {
namespace {

// Counts the nodes of one document as its events arrive, each alias as the size of the node
// it names, and throws at the node where the count passes the limit.
class NodeCounter final : public YAML::EventHandler {
 public:
  NodeCounter(const std::string& file, std::size_t max_nodes) : file_(file), max_(max_nodes) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor, "?"); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                const std::string& value) override {
    leaf(mark, anchor, value);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    for (const Frame& f : stack_) {
      if (f.anchor == anchor && anchor != YAML::NullAnchor) {
        fail(mark, "an alias inside the node it names (a cycle)");
      }
    }
    const auto it = sizes_.find(anchor);
    add(mark, it == sizes_.end() ? 1 : it->second);
    child_done("?");
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(mark, anchor, false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    open(mark, anchor, true);
  }
  void OnMapEnd() override { close(); }

  [[nodiscard]] std::size_t total() const noexcept { return total_; }

 private:
  struct Frame {
    bool map = false;
    bool key_next = true;       // a map: the next node is a key
    std::string key;            // a map: the key of the value being read
    std::size_t index = 0;      // a list: the index of the item being read
    std::size_t total_at_start = 0;
    YAML::anchor_t anchor = YAML::NullAnchor;
  };

  void leaf(const YAML::Mark& mark, YAML::anchor_t anchor, const std::string& text) {
    add(mark, 1);
    if (anchor != YAML::NullAnchor) sizes_[anchor] = 1;
    child_done(text);
  }

  void open(const YAML::Mark& mark, YAML::anchor_t anchor, bool map) {
    add(mark, 1);
    Frame f;
    f.map = map;
    f.total_at_start = total_ - 1;
    f.anchor = anchor;
    stack_.push_back(std::move(f));
  }

  void close() {
    const Frame f = std::move(stack_.back());
    stack_.pop_back();
    if (f.anchor != YAML::NullAnchor) sizes_[f.anchor] = total_ - f.total_at_start;
    child_done("?");
  }

  // The node just read (TEXT: its scalar, for a map key) is complete: its parent moves on.
  void child_done(const std::string& text) {
    if (stack_.empty()) return;
    Frame& p = stack_.back();
    if (!p.map) {
      ++p.index;
    } else if (p.key_next) {
      p.key = text;
      p.key_next = false;
    } else {
      p.key_next = true;
    }
  }

  void add(const YAML::Mark& mark, std::size_t n) {
    total_ += n;
    if (total_ > max_) {
      fail(mark, "more than " + std::to_string(max_) +
                     " nodes with aliases expanded (the limit of a configuration file)");
    }
  }

  // The key path of the node being read: "plugins[0].params.x".
  [[nodiscard]] std::string path() const {
    std::string p;
    for (const Frame& f : stack_) {
      if (!f.map) {
        p += "[" + std::to_string(f.index) + "]";
      } else {
        if (!p.empty()) p += ".";
        p += f.key_next ? std::string("?") : f.key;
      }
    }
    return p.empty() ? std::string("(document)") : p;
  }

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& reason) const {
    throw ConfigError(SourceLoc{file_, mark.line + 1, mark.column + 1}, path(), reason);
  }

  const std::string& file_;
  std::size_t max_;
  std::size_t total_ = 0;
  std::vector<Frame> stack_;
  std::unordered_map<YAML::anchor_t, std::size_t> sizes_;  // anchored node -> its expanded size
};

}  // namespace

void check_yaml_size(const std::string& text, const std::string& file, const YamlBounds& bounds) {
  if (text.size() <= bounds.max_bytes) return;
  const auto end = text.begin() + static_cast<std::ptrdiff_t>(bounds.max_bytes);
  const int line = 1 + static_cast<int>(std::count(text.begin(), end, '\n'));
  const auto last_nl = std::find(std::make_reverse_iterator(end), text.rend(), '\n');
  const int column = 1 + static_cast<int>(std::distance(last_nl.base(), end));
  throw ConfigError(SourceLoc{file, line, column}, "(file)",
                    "larger than " + std::to_string(bounds.max_bytes) +
                        " bytes (the limit of a configuration file)");
}

namespace {
[[noreturn]] void syntax_error(const std::string& file, const YAML::Exception& e) {
  throw ConfigError(SourceLoc{file, e.mark.line + 1, e.mark.column + 1}, "(syntax)", e.msg);
}
}  // namespace

std::size_t count_yaml_nodes(const std::string& text, const std::string& file, const YamlBounds& bounds) {
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    NodeCounter counter(file, bounds.max_nodes);
    parser.HandleNextDocument(counter);
    return counter.total();
  } catch (const YAML::Exception& e) {
    syntax_error(file, e);
  }
}

bool node_count_cannot_pass(const std::string& text, const YamlBounds& bounds) noexcept {
  return text.find('*') == std::string::npos && (text.size() + 1) * kMaxNodesPerByte <= bounds.max_nodes;
}

YAML::Node load_bounded_yaml(const std::string& text, const std::string& file,
                             const YamlBounds& bounds) {
  check_yaml_size(text, file, bounds);
  try {
    // The counting pass parses the whole text once more: only where its limit can be passed.
    if (!node_count_cannot_pass(text, bounds)) (void)count_yaml_nodes(text, file, bounds);
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    syntax_error(file, e);
  }
}

}  // namespace crease::config
