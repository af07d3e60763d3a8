#include "core/daemon/sequences.h"

#include <doctest/doctest.h>

#include <cstring>

#include "core/port.h"
#include "core/port_types/sequence_status.h"

using crease::SequenceStatus;

TEST_CASE("every SequenceStatus port is shown with its path, phase, time in state and last reason") {
  crease::PortRegistry ports;
  auto* ch = ports.bind_latest_writer("fold.status", crease::port_type_of<SequenceStatus>(), "fold");
  (void)ports.bind_latest_writer("other", crease::PortType{"crease.test.Value", 1, 24}, "x");
  CHECK(crease::daemon::sequences_view(ports).empty());  // nothing written yet
  SequenceStatus s{};
  std::strcpy(s.path, "fold/bend/follow_via[3]");
  std::strcpy(s.why, "via point reached");
  std::strcpy(s.fold, "half");
  s.phase = SequenceStatus::running;
  s.time_in_state_s = 1.25;
  s.transitions = 14;
  std::memset(s.fold + 4, 'x', sizeof s.fold - 4);  // unterminated text is cut at its array's end
  ch->write(&s, 1);
  const auto v = crease::daemon::sequences_view(ports);
  REQUIRE(v.size() == 1);
  CHECK(v[0]["port"] == "fold.status");
  CHECK(v[0]["path"] == "fold/bend/follow_via[3]");
  CHECK(v[0]["phase"] == "running");
  CHECK(v[0]["time_in_state_s"] == 1.25);
  CHECK(v[0]["why"] == "via point reached");
  CHECK(v[0]["transitions"] == 14);
  CHECK(v[0]["fold"].get<std::string>().size() == sizeof s.fold);
}
