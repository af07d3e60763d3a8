// The state tables: every state of the fold reaches abort, every state but the three resting
// ones has a timeout in the shipped folds, the success rows lead from idle to done through
// steps (a)-(h) in order, and the paths print as creasectl status shows them.
#include "plugins/fold_sequence/states.h"

#include <doctest/doctest.h>

#include <cstring>
#include <set>
#include <string>

using namespace crease::fold;

namespace {
bool reaches_abort(S s) {
  for (S x = s; x != S::root; x = state_info(x).parent)
    for (const Row* r = rows_of(x).begin; r != rows_of(x).end; ++r)
      if (r->ev == Ev::fault && r->to == S::abort) return true;
  return false;
}
std::string path(S s, int via = -1) {
  char buf[64];
  write_path(s, via, buf, sizeof buf);
  return buf;
}
}  // namespace

TEST_CASE("every state of the fold reaches abort on a fault, and has a way out on a timeout") {
  for (int i = 1; i < kStateCount; ++i) {
    const S s = static_cast<S>(i);
    CAPTURE(path(s));
    if (is_within(s, S::fold)) CHECK(reaches_abort(s));
    if (is_within(s, S::abort) && is_leaf(s)) {
      bool timeout = false;
      for (const Row* r = rows_of(s).begin; r != rows_of(s).end; ++r) timeout |= r->ev == Ev::timeout;
      CHECK(timeout);  // the retreat never hangs
    }
  }
}

TEST_CASE("the success rows lead from idle through (a)-(h) to done, every leaf of the fold on the way") {
  // Once with the fixing hand shifting, once with the pinching one (the grasp's open, lift and
  // the fixing hand's approach and contact): every leaf of the fold on one of the ways.
  std::set<S> seen;
  for (const bool pinching_shifts : {false, true}) {
    CAPTURE(pinching_shifts);
    S s = S::idle;
    int via = 0;
    for (int guard = 0; guard < 200 && s != S::done; ++guard) {
      seen.insert(s);
      const Row* next = nullptr;
      for (const Row* r = rows_of(s).begin; r != rows_of(s).end; ++r) {
        if (r->ev == Ev::timeout || r->ev == Ev::fault || is_within(r->to, S::abort)) continue;
        if (s == S::shift_press &&
            (r->guard == Guard::shifted_by_fixing || r->guard == Guard::shifted_by_pinching))
          continue;                                    // the slide's branch
        if (r->guard == Guard::slide_again) continue;  // one slide shifts it
        if (r->guard == (pinching_shifts ? Guard::shifted_by_fixing : Guard::shifted_by_pinching))
          continue;
        if (r->guard == Guard::more_via && via >= 4) continue;
        if (r->guard == Guard::last_via && via < 4) continue;
        next = r;
        break;
      }
      REQUIRE_MESSAGE(next != nullptr, path(s));
      if (next->to == s) ++via;
      S to = next->to;
      while (!is_leaf(to)) to = state_info(to).initial;
      s = to;
    }
    CHECK(s == S::done);
  }
  for (int i = 1; i < kStateCount; ++i) {
    const S x = static_cast<S>(i);
    if (is_leaf(x) && is_within(x, S::fold)) CHECK_MESSAGE(seen.count(x) == 1, path(x));
  }
}

TEST_CASE("paths") {
  CHECK(path(S::follow_via, 3) == "fold/bend/follow_via[3]");
  CHECK(path(S::follow_via, 12) == "fold/bend/follow_via[12]");
  CHECK(path(S::follow_via) == "fold/bend/follow_via");
  CHECK(path(S::abort_lift) == "abort/lift");
  CHECK(path(S::idle) == "idle");
  CHECK(state_by_path("fold/refixate/press") == S::refix_press);
  CHECK(state_by_path("fold/nothing") == S::count);
  char small[8];
  write_path(S::follow_via, 3, small, sizeof small);
  CHECK(std::string(small) == "fold/be");  // truncated, terminated
  CHECK(depth(S::follow_via) == 3);
  CHECK(std::string(reason_name(Reason::vision_lost)) == "vision_lost");
}
