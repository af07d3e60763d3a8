// Plugin `sheet_score`: scores a tracked sheet against the simulated world's truth, and records
// the tracked sheet, for any configuration that names it (the daemon knows no sheet).
//   input  sheet_state    (latest SheetState: the tracking model's sheet)
//   input  sheet_truth    (latest SheetState: the world's sheet; optional at run time)
//   output tracking_error (latest Figure: mean node distance, mm, per model frame)
// Parameters:
//   record   file to write every model frame to as one JSON line (state_recorder.h); default none
//   record_truth  file to write the truth to, the same way: each new truth state this plugin
//            reads (once per model frame at most); crease-score pairs the two files offline
//   label    the figure's name (default "tracking error of sheet_state vs sheet_truth")
// Run it in the model's loop after the model, so it sees every frame. update is RT-safe: the
// score is O(nodes); a recorded frame is copied into a bounded queue that a non-RT thread
// writes out (frames that find it full are counted and logged at deactivation).
#include <cstring>
#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/figure.h"
#include "core/port_types/sheet_state.h"
#include "plugins/sheet_score/node_error.h"
#include "plugins/sheet_score/state_recorder.h"
#include "rt/clock.h"

namespace {
using namespace crease;

class SheetScore final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    const std::string label = p.get<std::string>("label", "tracking error of sheet_state vs sheet_truth");
    if (label.empty() || label.size() >= sizeof(Figure::label)) p.fail("label", "must have 1 to 63 characters");
    std::strncpy(figure_.label, label.c_str(), sizeof(figure_.label) - 1);
    std::strncpy(figure_.unit, "mm", sizeof(figure_.unit) - 1);
    std::strncpy(figure_.sample, "model frames", sizeof(figure_.sample) - 1);
    if (p.has("record")) {
      const std::string path = p.get<std::string>("record");
      try {
        recorder_ = std::make_unique<sheet_score::StateRecorder>(path, rt::now_ns());
      } catch (const std::exception& e) {
        p.fail("record", e.what());
      }
    }
    if (p.has("record_truth")) {
      const std::string path = p.get<std::string>("record_truth");
      try {
        truth_recorder_ = std::make_unique<sheet_score::StateRecorder>(path, rt::now_ns());
      } catch (const std::exception& e) {
        p.fail("record_truth", e.what());
      }
    }
    model_ = ports.latest_input<SheetState>("sheet_state");
    truth_ = ports.latest_input<SheetState>("sheet_truth");
    out_ = ports.latest_output<Figure>("tracking_error", figure_);  // safe value: named, no samples
  }

  Status update(const Cycle& cycle) override {
    const rt::ReadInfo m = model_.poll();
    if (!m.has_data()) return Status::degraded;
    if (!m.is_new()) return Status::ok;
    const SheetState& s = model_.value();
    if (recorder_ && !recorder_->record_rt(s) && s.nodes_u != 0) ++dropped_;
    const rt::ReadInfo t = truth_.poll();
    if (truth_recorder_ && t.is_new() && !truth_recorder_->record_rt(truth_.value()) && truth_.value().nodes_u != 0)
      ++dropped_truth_;
    if (t.has_data()) {
      const double err = sheet_score::mean_node_distance_mm(s, truth_.value());
      if (err >= 0) {
        ++figure_.count;
        figure_.sum += err;
        figure_.last = err;
        if (err > figure_.max) figure_.max = err;
        out_.write(figure_, cycle.time_ns);
      }
    }
    return Status::ok;
  }

  void deactivate() override {
    if (truth_recorder_) {
      truth_recorder_->stop();
      log_rt(rt::LogLevel::info, "truth frames recorded", static_cast<std::int64_t>(truth_recorder_->recorded()));
      if (dropped_truth_ != 0) log_rt(rt::LogLevel::warn, "truth frames not recorded (queue full)", dropped_truth_);
    }
    if (!recorder_) return;
    recorder_->stop();
    log_rt(rt::LogLevel::info, "model frames recorded", static_cast<std::int64_t>(recorder_->recorded()));
    if (dropped_ != 0) log_rt(rt::LogLevel::warn, "model frames not recorded (queue full)", dropped_);
  }

 private:
  LatestInput<SheetState> model_;
  LatestInput<SheetState> truth_;
  LatestOutput<Figure> out_;
  Figure figure_{};
  std::unique_ptr<sheet_score::StateRecorder> recorder_, truth_recorder_;
  std::int64_t dropped_ = 0, dropped_truth_ = 0;
};
}  // namespace

CREASE_PLUGIN(SheetScore, "sheet_score", "1.0.0")
