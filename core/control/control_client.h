// A blocking client of the control socket (creasectl, tests, benchmarks). Not for RT threads.
//
//   crease::control::ControlClient client(crease::control::default_socket_path());
//   nlohmann::json reply = client.request({{"cmd", "status"}});   // {"id":1,"ok":true,...}
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace crease::control {

class ClientError : public std::runtime_error {
 public:
  enum class Kind {
    not_running,  // no socket file, or nobody listening
    permission,   // the socket file is not accessible to us
    io,           // read/write failed or the daemon closed the connection
    timeout,      // no reply in time
    protocol,     // the reply is not a JSON object
  };
  ClientError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  [[nodiscard]] Kind kind() const noexcept { return kind_; }

 private:
  Kind kind_;
};

class ControlClient {
 public:
  // Connects to PATH. @throws ClientError (not_running / permission / io)
  explicit ControlClient(const std::string& path,
                         std::chrono::milliseconds timeout = std::chrono::seconds(10));
  ~ControlClient();
  ControlClient(const ControlClient&) = delete;
  ControlClient& operator=(const ControlClient&) = delete;

  // Sends REQUEST (an "id" is added when absent) and returns the reply object.
  // A refusal by the server (e.g. permission_denied) is a normal reply with "ok": false.
  // @throws ClientError
  [[nodiscard]] nlohmann::json request(nlohmann::json request);

  // Raw access for tests: send bytes as they are; read one line (without '\n'),
  // std::nullopt when the server closed the connection.
  void send_raw(const std::string& bytes);
  [[nodiscard]] std::optional<std::string> read_line();

  [[nodiscard]] int fd() const noexcept { return fd_; }

 private:
  int fd_ = -1;
  std::chrono::milliseconds timeout_;
  std::string inbuf_;
  std::int64_t next_id_ = 1;
  std::string path_;
};

}  // namespace crease::control
