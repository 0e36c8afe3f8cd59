#pragma once
// The audit behind `handcentric audit` and the main report: classify representations (the
// built-ins, ActionFlow's target, or a plug-in), then render one table per representation and
// view (a row per component and mode, a column per group, a mark and the largest error; notes,
// injectivity and failing cells' witnesses below) or the JSON document of docs/AUDIT.md.
#include <memory>
#include <ostream>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/observation/workspace.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"

namespace handcentric::props {

/// The arithmetic a map is computed in, which sets the pointwise tolerance and the unit of
/// rounding of the rounding probe (tolerance.hpp).
enum class Precision { float64, float32, bfloat16, float16 };

/// "float64", "float32", "bfloat16" or "float16"; throws InvalidArgument naming the value, the
/// option as the caller spells it (`option`: "--precision" on the command line, "precision" in
/// Python) and the names otherwise.
Precision parse_precision(const std::string& name, const Spelling& spelling = kCommandLineSpelling);

/// The unit roundoff of a precision: 2^-53, 2^-24, 2^-8 (bfloat16), 2^-11 (float16).
double unit_roundoff(Precision precision);

/// The unit of rounding the rounding probe moves inputs by (check.hpp, step 2): the precision's
/// own for float64 and float32; float32's for the 16-bit formats. A 16-bit pipeline as shipped
/// runs its network in 16 bits on hand-frame inputs, which are the same for o and g o, and does
/// its world-frame arithmetic in float32 or better. Probing at 2^-8 would excuse any leak the
/// network is sensitive to: a 2 cm world-frame leak behind a bfloat16 network passed pointwise
/// so, while the law check found it. A pipeline that takes world-frame differences in 16 bits
/// is not equivariant up to its output's rounding (its network amplifies that rounding) and gets
/// NO.
double probe_unit_roundoff(Precision precision);

/// The REL of a precision's pointwise floor: kRelativeTolerance (float64),
/// kFloat32RelativeTolerance, kHalfPrecisionRelativeTolerance (both 16-bit formats).
double precision_relative_tolerance(Precision precision);

struct AuditOptions {
  std::vector<Group> groups = all_groups();
  std::vector<View> views = {View::eye_in_hand, View::third_person};
  int cases = kDefaultCases;  ///< pointwise cases per cell
  /// The frequency the cases were set from (--detect, detect=: cases_to_detect); none: `cases`
  /// was given or is the default. Only the header says it; the cells state their own.
  std::optional<double> detect;
  /// Seeds everything the audit draws: the cases, a policy's noise per case, the laws' draws.
  std::uint64_t seed = 1;
  /// A whole policy's in-distribution tests on every cell (--test-law); by default a cell whose
  /// pointwise check holds takes its law from it (policy_audit.hpp, Method::from_pointwise).
  bool test_law = false;
  Precision precision = Precision::float64;
  /// REL of the tolerance REL * (1 + L); 0 = from `precision` (precision_relative_tolerance).
  double relative_tolerance = 0.0;
  /// How the caller names the options in messages (spelling.hpp).
  Spelling spelling = kCommandLineSpelling;
  /// Draw every case inside this box, g * scene included (workspace.hpp); none: anywhere.
  std::optional<Workspace> workspace;
  /// Draw every scene from these (observation/recorded.hpp); none: random scenes.
  std::shared_ptr<const RecordedObservations> observations;
  /// A closed loop runs beside the single calls (--episodes with --policy-exec): recorded
  /// observations with an 'episode' index are then its episodes (recorded_episodes.hpp);
  /// without one such data are refused.
  bool closed_loop = false;
};

/// The label of a verdict table's row: "policy", "policy (in distribution)", "policy (closed
/// loop)" (the text tables and the report page).
std::string row_label(Component component, Mode mode);

/// The one note for a policy's in-distribution cells whose law follows from their pointwise
/// "yes" (Method::from_pointwise): `count` of them, shown as `marked` ("(marked =)" in text).
std::string derived_laws_note(long count, const std::string& marked);

/// `cases` when 1 <= cases <= kMaxCases (run.hpp); else InvalidArgument naming --cases, the value
/// and the bound, in one line. Wide enough to take an unchecked command-line number.
int checked_cases(long long cases, const Spelling& spelling = kCommandLineSpelling);

/// The fewest (scene, g) cases whose pointwise "yes" finds, with 99% probability, a breaking
/// that occurs in at least `frequency` of the draws: ceil(ln 0.01 / ln(1 - frequency)) (459 for
/// 0.01, 4603 for 0.001), the inverse of detectable_frequency (verdict.hpp) over all the draws.
/// InvalidArgument naming --detect and the value for a frequency outside (0, 1) or one that
/// needs more than kMaxCases cases.
int cases_to_detect(double frequency, const Spelling& spelling = kCommandLineSpelling);

/// The REL an audit uses: options.relative_tolerance if set, else the precision's. Throws
/// InvalidArgument for a negative, non-finite or >= 1 tolerance.
double audit_relative_tolerance(const AuditOptions& options);

/// The names `--repr` accepts: the four built-ins, then "actionflow".
std::vector<std::string> auditable_names();

/// Classifier options for an audit: options.views, options.groups, the tolerance of
/// audit_relative_tolerance; pointwise cells run options.cases cases, distribution cells
/// max(10, ceil(cases / 100)), injectivity max(100, cases / 5) chunk pairs and a resolution
/// scan on max(10, pairs / 8) scenes.
ClassifierOptions classifier_options(const AuditOptions& options);

/// classifier_options for a plug-in after its hello: the extra poses and scalars it asked for,
/// and prefetch passes when it answers batches (capabilities.batch > 0; the caller then wraps it
/// in a BatchedRepresentation or BatchedPolicy of that size). Throws InvalidArgument for a name
/// the recorded observations (options.observations) do not record: the pipe would fill it with
/// a placeholder the data never had.
ClassifierOptions plugin_classifier_options(const AuditOptions& options,
                                            const PluginCapabilities& capabilities);

/// Audits the named built-ins (empty = all of auditable_names()). Throws InvalidArgument
/// naming an unknown name and the valid ones.
std::vector<Classification> audit_builtins(const std::vector<std::string>& names,
                                           const AuditOptions& options);

/// Human output: per classification, one table per view, then notes, injectivity (a loud
/// warning when a map is not injective, naming its resolution when it loses information below
/// one) and, with `witnesses`, the failing cells' witnesses.
/// `witnesses` = false prints the tables and the warnings only (the main report).
void print_audit(std::ostream& out, const std::vector<Classification>& classifications,
                 const AuditOptions& options, bool witnesses = true);

/// {"representations": [{"name": ..., "injective": true|false|null, "summary": {view:
/// {component: {mode: {group: bool}}}}, "checks": [{"component", "group", "mode", "view",
/// "method", "invariant", "max_error", "cases", "seed", "witness", ...}]}]} (docs/AUDIT.md).
std::string audit_json(const std::vector<Classification>& classifications);

}  // namespace handcentric::props
