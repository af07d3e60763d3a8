// What a MockCanBus node and its MockCanBroker share. Internal to the mock bus.
//
// Data path: two single-producer single-consumer rings of Records in a shared-memory segment
// (memfd) the node creates and hands to the broker with its hello: `tx` (node -> broker) and
// `rx` (broker -> node). A send is a copy into `tx` and costs no system call unless the broker
// sleeps (ReactorShm::sleeping): then the first sender writes the broker's eventfd.
// Control path: the AF_UNIX SOCK_SEQPACKET connection ("\0crease-can/<name>") carries the
// hello (with the memfd), the broker's welcome (with its eventfd and ReactorShm memfd) and
// 1-byte doorbells that make the node's socket readable when `rx` got records while
// `rx_signalled` was 0. Its hang-up tells either side that the other is gone.
// Access: the broker checks each connecting node's credentials before anything else, and the
// node checks the broker's (mock_access.h); a refused node gets kRefused and a hang-up.
#pragma once

#include <sys/socket.h>
#include <sys/un.h>

#include <atomic>
#include <cstdint>
#include <string>

#include "drivers/can/can_frame.h"

namespace crease::drivers::mockwire {

enum Kind : std::uint32_t {
  kData = 0,     // a CAN frame (or an error frame, CAN_ERR_FLAG) on the bus
  kHello = 1,    // node -> broker (socket, with the NodeShm memfd): frame.can_id = node id
  kRestart = 2,  // node -> broker (tx ring): leave bus-off
  kWelcome = 3,  // broker -> node (socket, with its eventfd and ReactorShm memfd)
  kRefused = 4,  // broker -> node (socket): the node's user may not use this bus (then hang-up)
};

struct Record {
  std::uint32_t kind = kData;
  std::uint32_t node = 0;          // sender's node id (broker -> node: the original sender)
  std::int64_t timestamp_ns = 0;   // broker -> node: end of the frame on the virtual bus;
                                   // node -> broker: when the node sent it
  CanFrame frame;
};
static_assert(sizeof(Record) == 88);

// Lock-free SPSC ring of N Records (N a power of two); indices count records and wrap.
// Index stores and the loads of the other side's index are seq_cst: the sleep/wake flags
// (ReactorShm::sleeping, NodeShm::rx_signalled, rx_need_space) rely on store-then-load
// ordering between an index and a flag (no fences: ThreadSanitizer does not model them).
template <std::uint32_t N>
struct Ring {
  static_assert((N & (N - 1)) == 0);
  static_assert(std::atomic<std::uint32_t>::is_always_lock_free);
  alignas(64) std::atomic<std::uint32_t> head{0};  // written by the producer
  alignas(64) std::atomic<std::uint32_t> tail{0};  // written by the consumer
  struct alignas(64) Slot {
    Record rec;  // one record per two cache lines: no line shared by two records
  };
  Slot slots[N];

  // Producer side.
  [[nodiscard]] std::uint32_t free_slots() const noexcept {
    return N - (head.load(std::memory_order_relaxed) - tail.load(std::memory_order_seq_cst));
  }
  // Pushes n records the caller checked room for (free_slots() >= n), published at once.
  void push_n(const Record* r, std::uint32_t n) noexcept {
    const std::uint32_t h = head.load(std::memory_order_relaxed);
    for (std::uint32_t k = 0; k < n; ++k) slots[(h + k) % N].rec = r[k];
    head.store(h + n, std::memory_order_seq_cst);
  }
  bool try_push(const Record& r) noexcept {
    const std::uint32_t h = head.load(std::memory_order_relaxed);
    if (h - tail.load(std::memory_order_seq_cst) >= N) return false;
    slots[h % N].rec = r;
    head.store(h + 1, std::memory_order_seq_cst);
    return true;
  }
  // Consumer side.
  [[nodiscard]] std::uint32_t size() const noexcept {
    return head.load(std::memory_order_seq_cst) - tail.load(std::memory_order_relaxed);
  }
  [[nodiscard]] bool empty() const noexcept {
    return head.load(std::memory_order_seq_cst) == tail.load(std::memory_order_relaxed);
  }
  bool try_pop(Record& out) noexcept {
    const std::uint32_t t = tail.load(std::memory_order_relaxed);
    if (head.load(std::memory_order_seq_cst) == t) return false;
    out = slots[t % N].rec;
    tail.store(t + 1, std::memory_order_seq_cst);
    return true;
  }
};

inline constexpr std::uint32_t kShmMagic = 0x43414e32;  // "CAN2"
inline constexpr std::uint32_t kTxRing = 256;
inline constexpr std::uint32_t kRxRing = 1024;

// One node's segment (created and zero-filled by the node).
struct NodeShm {
  std::uint32_t magic = kShmMagic;
  std::uint32_t size = sizeof(NodeShm);
  Ring<kTxRing> tx;                               // node -> broker
  Ring<kRxRing> rx;                               // broker -> node
  alignas(64) std::atomic<std::uint32_t> rx_signalled{0};  // a doorbell is (or may be) pending on the socket
  std::atomic<std::uint32_t> rx_need_space{0};             // the broker holds records for a full rx ring:
                                                           // wake it once the ring is half empty
};

// The broker thread's page, shared by every node of every broker it serves.
struct ReactorShm {
  alignas(64) std::atomic<std::uint32_t> sleeping{0};  // 1: the broker waits for its eventfd
};

// Abstract-namespace AF_UNIX address for a bus name ("\0crease-can/<name>"). Throws if the
// name is empty or too long.
socklen_t make_address(const std::string& bus_name, sockaddr_un& out);

// One Record and up to kMaxFds descriptors (SCM_RIGHTS) over the control socket: the hello and
// the welcome. Both return sendmsg's / recvmsg's result, errno as the call left it.
inline constexpr int kMaxFds = 2;
ssize_t send_record(int sock, const Record& r, const int* fds, int nfds, int flags) noexcept;
// The descriptors arrive close-on-exec; a slot no descriptor came for is -1.
ssize_t recv_record(int sock, Record& r, int (&fds)[kMaxFds], int flags) noexcept;

}  // namespace crease::drivers::mockwire
