#include "handcentric/props/audit_header.hpp"

#include <string>

#include "handcentric/core/format.hpp"

namespace handcentric::props {
namespace {

// The name --precision takes for `precision`, read back through parse_precision so that the
// names stay in one place.
std::string precision_name(Precision precision) {
  for (const char* name : {"float64", "float32", "bfloat16", "float16"}) {
    if (parse_precision(name) == precision) return name;
  }
  return "float64";
}

}  // namespace

void print_audit_header(std::ostream& out, const AuditOptions& audit, bool policies) {
  const double relative = audit_relative_tolerance(audit);  // validates the tolerance
  const ClassifierOptions used = classifier_options(audit);
  out << "handcentric audit: " << audit.cases << " (scene, g) cases per pointwise cell"
      << (audit.detect
              ? " (" + audit.spelling.with_value("detect", format_shortest(*audit.detect), false) +
                    ": a breaking on that share of the draws is found with 99% "
                    "probability)"
              : std::string())
      << ", " << used.distribution.cases << " per in-distribution cell, seed " << audit.seed
      << "; tolerance " << relative << " (1 + L)"
      << (audit.relative_tolerance > 0.0 ? " (--tolerance)"
          : audit.precision != Precision::float64
              ? " (" + precision_name(audit.precision) + " rounding)"
              : std::string())
      << (audit.workspace ? "; every case inside the workspace " + audit.workspace->describe() +
                                ", g * scene too (--workspace)"
                          : std::string())
      << (audit.observations ? "; " + audit.observations->verdict_note() + " (--observations)"
                             : std::string())
      << "\n"
      << (policies ? "'yes' = equivariant, a(g o, n) = g a(o, n) (eq. 4); pointwise with the same "
                     "noise n, in distribution with n ~ N(0, I). "
                   : "'yes' = invariant. ")
      << "The number is the largest error seen: pointwise the largest difference between the "
         "two sides, in the component's units (m, rad or the map's own numbers); in "
         "distribution, exactly for maps affine in the noise, the larger difference of the two "
         "Gaussian laws' means and covariances, else (marked ~: decided wholly or partly by the "
         "energy, paired mean and scale tests at level "
      << used.distribution.family_alpha
      << " per cell) the energy distance of the tested coordinates (a statistic, not a length)"
      << (policies ? "; marked =: a law that follows from the pointwise cell (the same number)"
                   : "")
      << ". Rules: docs/AUDIT.md\n\n";
}

}  // namespace handcentric::props
