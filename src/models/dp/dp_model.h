// The dp model: creeping flow of the DP(mu, Bi) rheology (Daviet & Bertails-Descoubes 2016,
// Sections 4.1-4.5) with P2 velocity and P1d stress (constraints at quadrature points, Property 3)
// or P1 stress (constraints at the nodes, trapezoidal rule 4.3.5), solved without regularisation by
// the Cadoux fixed point (projected-gradient or interior-point steps) or an interior point.
#pragma once

#include "core/logger.h"
#include "core/output.h"
#include "models/dp/dp_parameters.h"

#include <nlohmann/json.hpp>

namespace granflow::dp
{
  /// Scalar results a caller (the CLI, a test, a benchmark) reads after a run; also in summary.json.
  struct Results
  {
    nlohmann::json summary;
  };

  /// Runs one case: mesh, assembly, solve, postprocessing, output. Throws InputError on bad input
  /// (before anything is written) and ConvergenceError when the solver fails (after writing what
  /// it has).
  Results
  run(const Parameters &parameters, OutputDirectory &output, Logger &log);
} // namespace granflow::dp
