#pragma once
/// mpm-prep --target-error. For a Taylor bar like V2 (a cylinder onto a rigid
/// frictionless wall, similar to V2 in every dimensionless group of the problem) the cell size
/// and particles per cell that reach a target error against the experiment at the least cost,
/// from the trade study's convergence fit (examples/trade/taylor_fit.toml, compiled in); any
/// other scene is told there is no fit for it.
#include <string>
#include <vector>

#include "mpm/scene/scene.hpp"

namespace mpm {

/// What --target-error proposes for a scene.
struct TargetProposal {
  double target = 0;                   ///< the target, a fraction
  std::vector<std::string> overrides;  ///< --set values that make the scene the proposal
  double cell_size = 0;                ///< m
  int particles_per_cell = 0;          ///< per axis
  double predicted_error = 0;          ///< fraction, max of |L| and |D| against the experiment
  double predicted_L_error = 0, predicted_D_error = 0;  ///< signed fractions
  double margin_L = 0, margin_D = 0;  ///< twice the scatter of the study's runs, fractions
  double ns_per_particle_step = 0;    ///< CPU ns of one thread per particle-step, measured
  std::string model;                  ///< "axisymmetric" or "3d"
  std::string fit_source;             ///< the fit's provenance, one line
  std::vector<std::string> notes;     ///< lines for the summary (reachable elsewhere, range)
};

/// The cheapest setting whose predicted error is at most `target` (a fraction, 0.02 for 2%).
/// Throws InputError at --target-error when the scene is not a V2-like Taylor bar (naming the
/// first thing that differs) or when no cell size reaches the target (with the fit's floor).
TargetProposal propose_for_target(const Scene& scene, double target);

/// Prints the proposal and its predicted cost (particle-steps from mpm-prep's own estimate of
/// the proposed model) on stderr.
void print_proposal(const TargetProposal& p, double particle_steps);

/// Parses "2%", "2 %" or "2" (percent) for --target-error; throws InputError otherwise.
double parse_target_error(const std::string& text);

}  // namespace mpm
