#include "dds_log.h"

#include <dds/dds.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace crease::dds_bridge {

namespace {
thread_local DdsLog::Capture* t_capture = nullptr;
}  // namespace

DdsLog& DdsLog::instance() {
  static DdsLog log;
  return log;
}

DdsLog::Capture::Capture() : outer_(t_capture) { t_capture = this; }
DdsLog::Capture::~Capture() { t_capture = outer_; }

void DdsLog::acquire() {
  const std::lock_guard lock(mu_);
  if (users_++ == 0) {
    dds_set_log_sink(
        [](void* self, const dds_log_data_t* d) { static_cast<DdsLog*>(self)->on_message(d->message, d->size); },
        this);
  }
}

void DdsLog::release() {
  bool last = false;
  {
    const std::lock_guard lock(mu_);
    last = --users_ == 0;
  }
  // Synchronous: Cyclone no longer calls the sink when this returns.
  if (last) dds_set_log_sink(nullptr, nullptr);
}

void DdsLog::watch(const std::string& topic, const std::string& type_name, std::atomic<std::uint64_t>* counter) {
  const std::lock_guard lock(mu_);
  watches_.push_back(Watch{" " + topic + "/" + type_name + " ", " " + type_name + " failed in type conversion", counter});
}

void DdsLog::unwatch(const std::atomic<std::uint64_t>* counter) {
  const std::lock_guard lock(mu_);
  std::erase_if(watches_, [&](const Watch& w) { return w.counter == counter; });
}

void DdsLog::on_message(const char* message, std::size_t size) {
  const std::string_view text(message, size);
  std::fwrite(message, 1, size, stderr);
  if (t_capture != nullptr) t_capture->text_.append(text);
  // From the network: "data(application, …): … deserialization <topic>/<type> failed (<why>)";
  // inside the process: "local: deserialization of <topic>/<type> as …" or
  // "local: deserialization <type> failed in type conversion".
  if (text.find("deserialization") == std::string_view::npos) return;
  const std::lock_guard lock(mu_);
  for (const Watch& w : watches_) {
    if (text.find(w.needle) != std::string_view::npos || text.find(w.local_needle) != std::string_view::npos)
      w.counter->fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace crease::dds_bridge
