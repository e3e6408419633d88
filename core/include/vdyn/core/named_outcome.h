#pragma once
// A run that ends in a named outcome instead of a number: the question has no
// answer where it was asked, and that is a result about the vehicle, not a
// failure of the program (e.g. a steady state asked for past the fold of the
// branch from straight running). It is an Error (a run that only wants a
// number stops with its message), and a sweep gives its row the outcome's
// status instead of "failed" (vdyn/core/sweep.h).
#include <algorithm>
#include <string>
#include <vector>

#include "vdyn/core/error.h"

namespace vdyn {

/// The statuses a NamedOutcome carries:
///  - beyond_fold: no steady state on the branch from straight running: the
///    branch folds back before the asked command (solveFromStraightRunning);
///  - past_lift_off: the branch from straight running ends where a wheel's
///    normal load reaches zero, before the asked command.
inline const std::vector<std::string>& namedOutcomeStatuses() {
  static const std::vector<std::string> s = {"beyond_fold", "past_lift_off"};
  return s;
}

inline bool isNamedOutcomeStatus(const std::string& status) {
  const auto& s = namedOutcomeStatuses();
  return std::find(s.begin(), s.end(), status) != s.end();
}

class NamedOutcome : public Error {
 public:
  /// `status`: one of namedOutcomeStatuses() (else an Error naming it); `message`
  /// says what has no answer, where (e.g. the fold's steer angle) and why.
  NamedOutcome(const std::string& status, const std::string& message) : Error(message), status_(status) {
    if (!isNamedOutcomeStatus(status)) throw Error("NamedOutcome: unknown status '" + status + "'");
  }
  const std::string& status() const { return status_; }

 private:
  std::string status_;
};

}  // namespace vdyn
