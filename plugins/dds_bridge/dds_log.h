// The process's Cyclone DDS log sink while a bridge is alive (non-RT; Cyclone calls it on its
// own threads). It writes every message to stderr as Cyclone's default sink does, counts the
// warnings Cyclone logs when its deserializer refuses a sample of a watched topic (an oversized
// bounded sequence, a truncated CDR stream: Cyclone drops those before any reader sees them),
// and captures the messages logged on a thread that asked for them (the reason Cyclone gives
// for refusing an XML configuration).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace crease::dds_bridge {

class DdsLog {
 public:
  static DdsLog& instance();

  // Installs the sink while at least one user holds it (each bridge's domain does); the last
  // release restores Cyclone's default sink, before the plugin library can be unloaded.
  void acquire();
  void release();

  // Counts into *counter each refused sample of DDS topic `topic` of type `type_name` (as
  // "crease_msgs::msg::dds_::Keypoints_") until unwatch(counter).
  void watch(const std::string& topic, const std::string& type_name, std::atomic<std::uint64_t>* counter);
  void unwatch(const std::atomic<std::uint64_t>* counter);

  // Messages logged on the calling thread during its life (nests: the innermost one collects).
  class Capture {
   public:
    Capture();
    ~Capture();
    Capture(const Capture&) = delete;
    Capture& operator=(const Capture&) = delete;
    [[nodiscard]] const std::string& text() const noexcept { return text_; }

   private:
    friend class DdsLog;
    std::string text_;
    Capture* outer_;
  };

 private:
  DdsLog() = default;
  void on_message(const char* message, std::size_t size);

  std::mutex mu_;
  int users_ = 0;
  struct Watch {
    std::string needle;        // " <topic>/<type> ", as Cyclone's messages from the network spell it
    std::string local_needle;  // " <type> failed in type conversion": delivery inside the process,
                               // which names no topic (counted for every watched topic of the type)
    std::atomic<std::uint64_t>* counter;
  };
  std::vector<Watch> watches_;
};

}  // namespace crease::dds_bridge
