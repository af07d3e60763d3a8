#include "drivers/protocol/cia402.h"

#include <doctest/doctest.h>

#include <initializer_list>

using namespace crease::drivers::cia402;

TEST_CASE("statuswords decode to their states") {
  for (State s : {State::not_ready_to_switch_on, State::switch_on_disabled, State::ready_to_switch_on,
                  State::switched_on, State::operation_enabled, State::quick_stop_active,
                  State::fault_reaction_active, State::fault}) {
    CHECK_MESSAGE(state_from_statusword(statusword(s)) == s, to_string(s));
  }
}

TEST_CASE("switch on, enable, quick stop, fault and fault reset") {
  Machine m;
  m.power_up();
  CHECK(m.state() == State::switch_on_disabled);
  m.step(kCmdEnableOperation, false);  // enable without shutdown first: ignored
  CHECK(m.state() == State::switch_on_disabled);
  m.step(kCmdShutdown, false);
  CHECK(m.state() == State::ready_to_switch_on);
  m.step(kCmdSwitchOn, false);
  CHECK(m.state() == State::switched_on);
  m.step(kCmdEnableOperation, false);
  CHECK(m.operation_enabled());
  m.step(kCmdQuickStop, false);
  CHECK(m.state() == State::quick_stop_active);
  m.step(kCmdQuickStop, false);
  CHECK(m.state() == State::quick_stop_active);  // held until voltage is disabled
  m.step(kCmdDisableVoltage, false);
  CHECK(m.state() == State::switch_on_disabled);

  m.step(kCmdShutdown, false);
  m.step(kCmdEnableOperation, false);
  CHECK(m.operation_enabled());
  m.step(kCmdEnableOperation, true);  // a fault appears
  CHECK(m.state() == State::fault_reaction_active);
  m.step(kCmdEnableOperation, true);
  CHECK(m.state() == State::fault);
  m.step(kCmdFaultReset, true);  // reset while the fault persists: stays
  CHECK(m.state() == State::fault);
  m.step(kCmdFaultReset, false);  // bit still high: no rising edge
  CHECK(m.state() == State::fault);
  m.step(0, false);
  m.step(kCmdFaultReset, false);  // rising edge
  CHECK(m.state() == State::switch_on_disabled);
}
