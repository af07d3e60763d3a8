#include "tools/creasectl/sequence_command.h"

#include <array>
#include <memory>
#include <string_view>

namespace crease::ctl {
namespace {
constexpr std::array<std::string_view, 5> kWords = {"start", "pause", "resume", "abort", "step"};
}  // namespace

int sequence_command_code(const std::string& word) {
  for (std::size_t i = 0; i < kWords.size(); ++i)
    if (kWords[i] == word) return static_cast<int>(i) + 1;
  return 0;
}

void add_sequence_command(CLI::App& app, std::string& cmd, nlohmann::json& request) {
  struct Args {
    std::string word, instance = "fold";
  };
  auto args = std::make_shared<Args>();
  auto* sub = app.add_subcommand("sequence", "steer a folding sequence: start, pause, resume, abort, step");
  sub->add_option("COMMAND", args->word, "start | pause | resume | abort | step (one state at a time)")
      ->required()
      ->check(CLI::IsMember({"start", "pause", "resume", "abort", "step"}));
  sub->add_option("--instance", args->instance, "the fold_sequence instance")->capture_default_str();
  sub->callback([args, &cmd, &request] {
    cmd = "param";
    request = {{"cmd", "param"},
               {"action", "set"},
               {"instance", args->instance},
               {"key", "command"},
               {"value", sequence_command_code(args->word)}};
  });
}

}  // namespace crease::ctl
