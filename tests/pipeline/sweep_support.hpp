// Meshes one realistic case and checks it (the robustness sweep of issue 12), in this process or in a
// forked child (crashes and hangs become outcomes instead of ending the run).
#pragma once
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>

#include "fvcheck/lib/report.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "realistic_cases.hpp"

namespace hm::testing {

enum class Outcome { Meshed, CheckFailed, Refused, Failed, Crash, Hang };
inline const char* outcome_name(Outcome o) {
  switch (o) {
    case Outcome::Meshed: return "meshed";
    case Outcome::CheckFailed: return "check-failed";
    case Outcome::Refused: return "refused";
    case Outcome::Failed: return "failed";
    case Outcome::Crash: return "crash";
    case Outcome::Hang: return "hang";
  }
  return "?";
}

/// How mesh_and_check reports checkMesh's figures of a meshed case in its reason: the largest face
/// skewness, the largest non-orthogonality (degrees) and the faces checkMesh fails for it (at 90 or more).
inline constexpr const char* kSkewnessTag = "checkMesh skewness ";
inline constexpr const char* kNonOrthogonalityTag = "non-orthogonality ";
inline constexpr const char* kNonOrthogonalityErrorsTag = "non-orthogonality errors ";
/// The transition cells' paper figures (issue 13 asks mean Q_S >= 0.3 and Q_O min >= 85 degrees):
/// their mean Q_S and their smallest Q_O(V) (boundary faces measured to their flux points).
inline constexpr const char* kTransitionQsTag = "transition Q_S mean ";
inline constexpr const char* kTransitionQoTag = "transition Q_O min ";
/// The number after `tag` in a reason, NaN when the reason has none.
inline double reported_figure(const std::string& reason, const std::string& tag) {
  const size_t at = reason.find(tag);
  return at == std::string::npos ? std::nan("") : std::atof(reason.c_str() + at + tag.size());
}
inline double reported_skewness(const std::string& reason) { return reported_figure(reason, kSkewnessTag); }
inline double reported_nonorthogonality(const std::string& reason) {
  return reported_figure(reason, kNonOrthogonalityTag);
}
/// checkMesh's non-orthogonality errors of a meshed case (0 when it has none).
inline double reported_nonorthogonality_errors(const std::string& reason) {
  const double v = reported_figure(reason, kNonOrthogonalityErrorsTag);
  return std::isnan(v) ? 0 : v;
}

struct CaseResult {
  Outcome outcome = Outcome::Failed;
  std::string reason;  ///< the error message or the failed checks
  double seconds = 0;
  std::vector<std::string> notes;  ///< the mesher's notes (in-process runs only)
};

/// Total volume of the box minus the exact wellbore holes (end caps as requested) of the case as
/// meshed (its permeability frame's, whose volumes are the physical ones: det S = 1).
inline double box_minus_holes(const CaseSpec& cs, const HybridMesh& h) {
  const ReservoirSpec& r = cs.reservoir;
  double v = (r.x.back() - r.x.front()) * (r.y.back() - r.y.front()) * (r.z.back() - r.z.front());
  const CaseSpec meshed = scaled_case(cs, h.frame);
  for (const WellBlock& b : h.blocks) v -= exact_wellbore_hole_volume(meshed, b.well, b.sectors);
  return v;
}

/// Runs `job` (which sets the outcome and reason of a case that meshed), timed; an InputError is a
/// Refused outcome, any other exception a Failed one, each with its message.
inline CaseResult run_classified(const std::function<void(CaseResult&)>& job) {
  CaseResult res;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    job(res);
  } catch (const InputError& e) {
    res.outcome = Outcome::Refused;
    res.reason = e.what();
  } catch (const std::exception& e) {
    res.outcome = Outcome::Failed;
    res.reason = e.what();
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

/// Meshes the case and checks: the builder matched every face, fvcheck passes (convexity,
/// conformity, closure, volumes, orthogonality, auto-centering, planarity) and the total volume is
/// the box minus the exact holes (relative 1e-9), every block closed as requested (a fallback to
/// flat ends counts as a failed check). Refusals (InputError) and failures are outcomes.
inline CaseResult mesh_and_check(const RealisticCase& rc) {
  return run_classified([&](CaseResult& res) {
    // As meshgen does: mesh in the local frame (a field-coordinate case is moved to its origin).
    CaseSpec user = rc.spec;
    const HybridMesh h = build_hybrid_mesh_in_local_frame(user);
    std::string bad;
    if (!h.build_report.ok) bad += "builder; ";
    for (const WellBlock& b : h.blocks)
      if (b.hemisphere_caps != (rc.spec.wells[b.well].end_caps == EndCaps::Hemisphere)) bad += "end caps not as requested; ";
    res.notes = h.notes;
    const FvReport fv = run_fvcheck(h.mesh, CheckOptions{}, h.cell_h_ref, &h.build_report);
    if (!fv.structure.ok) bad += "csr; ";
    for (const CheckResult& c : fv.checks)
      if (!c.ok()) bad += c.name + " " + std::to_string(c.violations) + "; ";
    // The domain meshed: the case's plan coordinates on the local frame's grid (local_frame.hpp).
    const double expected = box_minus_holes(local_case(rc.spec), h), got = total_volume(h.geometry);
    if (!(std::abs(got - expected) <= 1e-9 * expected)) bad += "volume " + std::to_string(got / expected - 1) + "; ";
    res.outcome = bad.empty() ? Outcome::Meshed : Outcome::CheckFailed;
    res.reason = bad;
    // For the before/after tables (docs/robustness.md): a mesh that passes would have failed the
    // boundary-face rule before session 6 (FV centre to face centroid, docs/fvcheck.md).
    for (const CheckResult& c : fv.checks)
      for (const auto& [k, v] : c.counts)
        if (res.outcome == Outcome::Meshed && k == "boundary_faces_below_threshold_at_centroid" && v > 0)
          res.reason = "passes; the centroid rule would fail " + std::to_string(v) + " boundary faces";
    // checkMesh's skewness (its limit is 4) and non-orthogonality (it fails a face at 90 degrees or
    // more), as fvcheck reproduces them, for the sweep's tally.
    if (res.outcome == Outcome::Meshed) {
      const NonOrthogonalitySummary& no = fv.openfoam_nonorthogonality;
      res.reason += (res.reason.empty() ? "" : "; ") + std::string(kSkewnessTag) + std::to_string(fv.openfoam_skewness.max) +
                    ", " + kNonOrthogonalityTag + std::to_string(no.max);
      if (no.errors > 0) res.reason += ", " + std::string(kNonOrthogonalityErrorsTag) + std::to_string(no.errors);
      for (const RegionQuality& rq : fv.by_region)
        if (rq.region == kTransition && rq.cells > 0)
          res.reason += ", " + std::string(kTransitionQsTag) + std::to_string(rq.q_s.mean) + ", " + kTransitionQoTag +
                        std::to_string(rq.q_o.min);
    }
  });
}

/// `job` in a forked child: a signal is a Crash, more than `timeout_s` a Hang.
inline CaseResult run_isolated(const std::function<CaseResult()>& job, double timeout_s) {
  int fds[2];
  if (pipe(fds) != 0) return {Outcome::Failed, "pipe() failed", 0, {}};
  const auto t0 = std::chrono::steady_clock::now();
  std::fflush(nullptr);  // else the child's copy of unwritten output is written again when it flushes
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const CaseResult r = job();
    const std::string msg = std::to_string(static_cast<int>(r.outcome)) + "\n" + r.reason;
    ssize_t left = static_cast<ssize_t>(msg.size());
    const char* p = msg.data();
    while (left > 0) {
      const ssize_t n = write(fds[1], p, static_cast<size_t>(left));
      if (n <= 0) break;
      left -= n, p += n;
    }
    _exit(0);
  }
  close(fds[1]);
  CaseResult res;
  int status = 0;
  bool done = false;
  while (!done) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) done = true;
    else if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      close(fds[0]);
      return {Outcome::Hang, "no result after " + std::to_string(timeout_s) + " s",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), {}};
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::string msg;
  char buf[4096];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) msg.append(buf, static_cast<size_t>(n));
  close(fds[0]);
  if (!WIFEXITED(status) || msg.empty()) {
    res.outcome = Outcome::Crash;
    res.reason = WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status)) : "no result";
    return res;
  }
  const size_t nl = msg.find('\n');
  res.outcome = static_cast<Outcome>(std::stoi(msg.substr(0, nl)));
  res.reason = msg.substr(nl + 1);
  return res;
}

/// mesh_and_check in a forked child (run_isolated).
inline CaseResult mesh_and_check_isolated(const RealisticCase& rc, double timeout_s) {
  return run_isolated([&] { return mesh_and_check(rc); }, timeout_s);
}

}  // namespace hm::testing
