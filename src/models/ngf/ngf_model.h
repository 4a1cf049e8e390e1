// The ngf model: quasi-static finite-deformation elasto-viscoplasticity with the nonlocal granular
// fluidity as a second nodal field (Henann & Kamrin 2016). Implicit increments, Newton-Raphson on
// the coupled (u, g) residual with the consistent tangent, increments adapted to convergence, run
// until the wall has moved the requested distance; steady velocity from displacement increments,
// mu_wall from the reactions of the driven wall, shear-band width.
#pragma once

#include "core/logger.h"
#include "core/output.h"
#include "models/ngf/ngf_parameters.h"

#include <nlohmann/json.hpp>

namespace granflow::ngf
{
  struct Results
  {
    nlohmann::json summary;
  };

  /// Runs one case. Throws InputError on bad input (before anything is written) and
  /// ConvergenceError when an increment cannot be completed (after writing the last converged
  /// state).
  Results
  run(const Parameters &parameters, OutputDirectory &output, Logger &log);
} // namespace granflow::ngf
