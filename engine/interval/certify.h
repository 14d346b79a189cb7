// Certificates for floating-point input (issue 44, SPEC section 5: analyze --certify): what
// interval arithmetic proves about the start as the file gives it (doubles are exact points),
// through the same term formulas (residual<T> in engine/evaluate_in.h, in Interval).
#pragma once

#include <limits>
#include <optional>
#include <string>

#include "engine/model.h"
#include "engine/rigidity.h"

namespace flexure::engine::certify {

struct StartCertificate {
  std::optional<bool> inf_rigid, flexible, prestress_stable;  // proved either way; unset: not proved
  // A proved lower bound of the smallest singular value of the rigidity matrix (equations
  // without row weights) on the complement of the trivial flexes; NaN when none.
  double sigma_lower_bound = std::numeric_limits<double>::quiet_NaN();
  std::string reason;
};

struct CertifyOptions {
  int index_base = 1;
  // The verified bounds form dense Gram matrices of the free coordinates (or of the equations):
  // up to this size.
  int max_dense = 2500;
};

// The certificate of the start x (free coordinates) of `model`; `numeric` is its double
// analysis, which only chooses what to try and words the reason when nothing is proved.
StartCertificate certifyStart(const Model& model, const Vector& x, const RigidityReport& numeric,
                              const CertifyOptions& options = {});

// The report with the certificate: its fields in rep.certificate, and a verdict that the
// certificate contradicts replaced by the proved one, with a warning (it must never happen).
void applyCertificate(RigidityReport& rep, const StartCertificate& c);

}  // namespace flexure::engine::certify
