// crease-trials: folding trials of the simulated robot, each scored from the world's truth.
//   crease-trials --trials 20 --seed 1 [--fold half|diagonal] [--jobs N] [--out DIR]
//                 [--config config/sim.yaml] [--plugin-dir DIR]... [--max-fold-s S]
// Trial k (0-based) runs in a process of its own (this program again, --child-trial k): the
// configuration's whole robot run by creased's body (core/daemon), its world drawn from seed
// SEED + k (the sheet's pose on the table, its stiffness and yield, every friction, the
// sensors' noise: sim_world's randomisation), the sequence started and followed to its end
// (trial_run.h). Each trial leaves DIR/trial_<k>/: result.json, creased.log and creased's
// report (report.html, .json, .txt). One row per trial as it ends, DIR/trials.json, after the
// last trial DIR/trials.html (trial_report.h), and last the summary line (trial_table.h). Exit
// status: 0 when every trial ran (whatever its score), 1 when a trial could not run, 2 for bad
// arguments.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "tools/trials/trial_json.h"
#include "tools/trials/trial_report.h"
#include "tools/trials/trial_run.h"
#include "tools/trials/trial_table.h"

extern char** environ;

namespace fs = std::filesystem;
using namespace crease::trials;

namespace {

std::string trial_dir(const std::string& out, int k) { return (fs::path(out) / ("trial_" + std::to_string(k))).string(); }

// The child: one trial in this process, its result in DIR/result.json.
int run_child(const TrialOptions& base, int k, std::uint64_t seed) {
  // Signals are taken by creased's body with sigtimedwait: blocked before any thread exists.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  signal(SIGPIPE, SIG_IGN);
  const TrialResult r = run_trial(base, k, seed);
  std::ofstream(fs::path(base.dir) / "result.json") << to_json(r).dump(1) << "\n";
  return r.error.empty() ? 0 : 1;
}

struct Child {
  pid_t pid = -1;
  int index = 0;
  std::uint64_t seed = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crease-trials: folding trials of the simulated robot, scored from the world's truth"};
  int trials = 1, jobs = 1, child_trial = -1;
  std::uint64_t seed = 1, child_seed = 0;
  bool faults = false;
  std::string out = "trials", log_level = "info";
  TrialOptions o;
  o.config = "config/sim.yaml";
  app.add_option("--trials", trials, "how many trials")->check(CLI::Range(1, 10000))->capture_default_str();
  app.add_option("--seed", seed, "trial k's world is drawn from seed + k")->capture_default_str();
  app.add_option("--fold", o.fold, "the sequence file folds/FOLD.yaml beside the configuration")
      ->check(CLI::IsMember({"half", "diagonal"}))
      ->capture_default_str();
  app.add_option("--jobs", jobs, "trials run at once (each a whole robot: its two loops take both CPUs of a "
                                 "2-CPU machine, so 1 there)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--out", out, "where each trial's directory and trials.json go")->capture_default_str();
  app.add_option("--config", o.config, "the simulated robot's configuration")->capture_default_str();
  app.add_option("--plugin-dir", o.plugin_dirs, "plugin directory (replaces the configuration's)");
  app.add_option("--max-fold-s", o.max_fold_s, "a sequence still running this long after its start is aborted "
                                               "(the operator's abort) and the trial fails")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--retain-s", o.retain_s, "after a finished fold, the retained angle is scored this much later")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_flag("--faults", faults, "bus faults (drops, corruption, a delay burst, a hand's bus-off) and camera dropouts");
  app.add_option("--log-level", log_level, "each trial's creased.log: trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}))
      ->capture_default_str();
  app.add_option("--child-trial", child_trial, "(internal) run trial K in this process")->group("");
  app.add_option("--child-seed", child_seed, "(internal) its seed")->group("");
  CLI11_PARSE(app, argc, argv);
  o.faults = faults;
  o.config = fs::absolute(o.config).string();
  for (auto& d : o.plugin_dirs) d = fs::absolute(d).string();
  out = fs::absolute(out).string();

  if (child_trial >= 0) {
    spdlog::set_level(spdlog::level::from_str(log_level));
    o.dir = trial_dir(out, child_trial);
    return run_child(o, child_trial, child_seed);
  }

  fs::create_directories(out);
  std::vector<TrialResult> results;
  std::map<pid_t, Child> running;
  int next = 0, failed = 0;
  const auto spawn = [&](int k) {
    const std::uint64_t s = seed + static_cast<std::uint64_t>(k);
    const std::string dir = trial_dir(out, k);
    fs::create_directories(dir);
    std::vector<std::string> args = {argv[0],         "--child-trial", std::to_string(k),  "--child-seed",
                                     std::to_string(s), "--fold",      o.fold,             "--out",
                                     out,             "--config",      o.config,           "--max-fold-s",
                                     std::to_string(o.max_fold_s),     "--retain-s",       std::to_string(o.retain_s),
                                     "--log-level",   log_level};
    if (o.faults) args.emplace_back("--faults");
    for (const auto& d : o.plugin_dirs) {
      args.emplace_back("--plugin-dir");
      args.push_back(d);
    }
    std::vector<char*> cargs;
    for (auto& a : args) cargs.push_back(a.data());
    cargs.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    const std::string log = (fs::path(dir) / "creased.log").string();
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, "/proc/self/exe", &fa, nullptr, cargs.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) {
      TrialResult r;
      r.index = k;
      r.seed = s;
      r.fold = o.fold;
      r.end = "error";
      r.error = std::string("cannot start the trial's process: ") + std::strerror(rc);
      judge(r);
      results.push_back(r);
      std::printf("%s\n", row(r).c_str());
      ++failed;
      return;
    }
    running[pid] = {pid, k, s};
  };
  while (next < trials || !running.empty()) {
    while (next < trials && static_cast<int>(running.size()) < jobs) spawn(next++);
    if (running.empty()) continue;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) break;
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const Child c = it->second;
    running.erase(it);
    TrialResult r;
    const fs::path result = fs::path(trial_dir(out, c.index)) / "result.json";
    try {
      std::ifstream in(result);
      r = from_json(nlohmann::json::parse(in));
    } catch (const std::exception& e) {
      r = TrialResult{};
      r.index = c.index;
      r.seed = c.seed;
      r.fold = o.fold;
      r.end = "error";
      r.error = "the trial's process ended (" +
                (WIFEXITED(status) ? "status " + std::to_string(WEXITSTATUS(status))
                                   : "signal " + std::to_string(WIFSIGNALED(status) ? WTERMSIG(status) : 0)) +
                ") without a result: see " + trial_dir(out, c.index) + "/creased.log";
      judge(r);
    }
    if (!r.error.empty()) ++failed;
    std::printf("%s\n", row(r).c_str());
    std::fflush(stdout);
    results.push_back(r);
  }
  std::sort(results.begin(), results.end(), [](const TrialResult& a, const TrialResult& b) { return a.index < b.index; });
  std::ofstream(fs::path(out) / "trials.json") << summary_json(results, o.fold, seed, faults).dump(1) << "\n";
  std::ofstream(fs::path(out) / "trials.html") << trials_html(results, o.fold, faults);
  std::printf("%s\n", summary_line(results, o.fold, faults).c_str());
  return failed == 0 ? 0 : 1;
}
