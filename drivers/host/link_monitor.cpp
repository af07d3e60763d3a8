#include "drivers/host/link_monitor.h"

namespace crease::drivers {

const char* to_string(LinkHealth h) noexcept {
  switch (h) {
    case LinkHealth::ok: return "ok";
    case LinkHealth::degraded: return "degraded";
    case LinkHealth::fault: return "fault";
  }
  return "unknown";
}

void LinkMonitor::begin_read() noexcept {
  fresh_this_cycle_ = false;
  crc_this_cycle_ = 0;
}

bool LinkMonitor::on_status(std::uint16_t cmd_seq, std::uint8_t sync_counter, std::uint32_t device_time_us) noexcept {
  // Acknowledge every pending command up to and including cmd_seq (seqs increase by one).
  for (int i = 0; i < pending_count_;) {
    const auto behind = static_cast<std::uint16_t>(cmd_seq - pending_seq_[i]);
    if (behind < 0x8000) {
      ++counters_.commands_acked;
      pending_seq_[i] = pending_seq_[pending_count_ - 1];
      pending_cycle_[i] = pending_cycle_[pending_count_ - 1];
      --pending_count_;
    } else {
      ++i;
    }
  }
  last_acked_ = cmd_seq;
  const bool time_advanced = !ever_fresh_ || static_cast<std::int32_t>(device_time_us - last_device_time_) > 0;
  const bool fresh = sync_counter == last_sync_sent_ && time_advanced && !fresh_this_cycle_;
  if (fresh) {
    fresh_this_cycle_ = true;
    ever_fresh_ = true;
    last_device_time_ = device_time_us;
    ++counters_.fresh;
  } else {
    ++counters_.stale;
  }
  return fresh;
}

void LinkMonitor::on_bad_crc() noexcept {
  ++crc_this_cycle_;
  ++counters_.bad_crc;
}

void LinkMonitor::on_emergency(bool active) noexcept {
  if (active) ++counters_.emergencies;
  emergency_ = active;
}

void LinkMonitor::end_read(bool bus_off) noexcept {
  const int slot = static_cast<int>(cycle_ % static_cast<std::uint64_t>(cfg_.crc_window_cycles));
  crc_in_window_ += crc_this_cycle_ - crc_ring_[slot];
  crc_ring_[slot] = crc_this_cycle_;
  silent_cycles_ = fresh_this_cycle_ ? 0 : silent_cycles_ + 1;
  // Commands not acknowledged within 2 cycles are reported failed.
  for (int i = 0; i < pending_count_;) {
    if (cycle_ - pending_cycle_[i] >= 1) {  // sent last cycle, not acked this cycle or the last
      ++counters_.commands_failed;
      pending_seq_[i] = pending_seq_[pending_count_ - 1];
      pending_cycle_[i] = pending_cycle_[pending_count_ - 1];
      --pending_count_;
    } else {
      ++i;
    }
  }
  // A bus-off episode: from the cycle the bus is found off until the device's next fresh status.
  if (bus_off) {
    if (bus_off_age_ < 0) {
      bus_off_age_ = 0;
      bus_off_faulted_ = false;
      ++counters_.bus_offs;
    } else {
      ++bus_off_age_;
    }
  } else if (bus_off_age_ >= 0) {
    if (fresh_this_cycle_) {
      if (!bus_off_faulted_) ++counters_.bus_offs_ridden;
      bus_off_age_ = -1;
    } else {
      ++bus_off_age_;
    }
  }
  const bool grace = bus_off_age_ >= 0 && bus_off_age_ < cfg_.bus_off_grace_cycles && ever_fresh_;
  if (bus_off_age_ >= 0 && !grace) bus_off_faulted_ = true;
  const LinkHealth before = health_;
  if ((bus_off && !grace) || emergency_ || crc_in_window_ > cfg_.crc_threshold ||
      (silent_cycles_ >= cfg_.timeout_cycles && !grace) || !ever_fresh_) {
    health_ = LinkHealth::fault;
    if (before != LinkHealth::fault && silent_cycles_ >= cfg_.timeout_cycles) ++counters_.timeouts;
  } else if (!fresh_this_cycle_ || crc_this_cycle_ > 0) {
    health_ = before == LinkHealth::fault ? LinkHealth::fault : LinkHealth::degraded;
    // Leaving fault needs a fresh cycle; a fault is not downgraded by a stale one.
  } else {
    health_ = LinkHealth::ok;
    if (before == LinkHealth::fault) ++counters_.recoveries;
  }
  ++cycle_;
}

void LinkMonitor::on_sent(std::uint16_t seq, std::uint8_t sync_counter) noexcept {
  last_sync_sent_ = sync_counter;
  ++counters_.commands_sent;
  if (pending_count_ == 4) {  // cannot happen with a 2-cycle deadline; keep the ring bounded
    ++counters_.commands_failed;
    pending_seq_[0] = pending_seq_[3];
    pending_cycle_[0] = pending_cycle_[3];
    --pending_count_;
  }
  pending_seq_[pending_count_] = seq;
  pending_cycle_[pending_count_] = cycle_;
  ++pending_count_;
}

}  // namespace crease::drivers
