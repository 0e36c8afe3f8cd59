#include "handcentric/props/audit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::props {
namespace {

std::string pad(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

std::string row_label(Component component, Mode mode) {
  return to_string(component) + (mode == Mode::distribution  ? " (in distribution)"
                                 : mode == Mode::closed_loop ? " (closed loop)"
                                                             : "");
}

std::string view_heading(View view, bool recorded) {
  if (recorded) {
    return view == View::eye_in_hand
               ? "eye-in-hand view (the recorded observations without their world points)"
               : "third-person view (the recorded observations, world points moving with g)";
  }
  return view == View::eye_in_hand ? "eye-in-hand view (no world points: Theorem 1's setting)"
                                   : "third-person view (1-8 world points that move with g)";
}

// "yes 3.1e-15" / "NO  2.0e+00": the mark and the largest error (in distribution: the larger
// difference of the laws' moments, or the energy distance, marked '~' when tests decided all or
// part of the cell, '=' when it follows from the pointwise cell).
std::string cell_text(const Verdict& verdict) {
  const std::string error = format_scientific(verdict.max_error, 1);
  const char* mark = verdict.method == Method::energy_test || verdict.method == Method::partly_exact
                         ? "~"
                     : verdict.method == Method::from_pointwise ? "="
                                                                : "";
  return std::string(verdict.invariant ? "yes " : "NO  ") +
         std::string(error.size() < 8 ? 8 - error.size() : 0, ' ') + error + mark;
}

std::string cell_name(const Verdict& verdict) {
  return row_label(verdict.component, verdict.mode) + " under " + to_string(verdict.group) + ", " +
         to_string(verdict.view);
}

std::string indent(const std::string& text, const std::string& prefix) {
  std::istringstream lines(text);
  std::string line, out;
  while (std::getline(lines, line)) out += prefix + line + "\n";
  return out;
}

}  // namespace

std::vector<std::string> auditable_names() {
  std::vector<std::string> names = builtin_representation_names();
  names.push_back("actionflow");
  return names;
}

Precision parse_precision(const std::string& name, const Spelling& spelling) {
  if (name == "float64") return Precision::float64;
  if (name == "float32") return Precision::float32;
  if (name == "bfloat16") return Precision::bfloat16;
  if (name == "float16") return Precision::float16;
  throw InvalidArgument("unknown " + spelling.option("precision") + " '" + name +
                        "'; use float64 (the default), float32, bfloat16 or float16: the "
                        "arithmetic the policy or representation is computed in");
}

double unit_roundoff(Precision precision) {
  switch (precision) {
    case Precision::float32:
      return kFloat32UnitRoundoff;
    case Precision::bfloat16:
      return kBfloat16UnitRoundoff;
    case Precision::float16:
      return kFloat16UnitRoundoff;
    case Precision::float64:
      break;
  }
  return kFloat64UnitRoundoff;
}

double probe_unit_roundoff(Precision precision) {
  return std::min(unit_roundoff(precision), kFloat32UnitRoundoff);
}

double precision_relative_tolerance(Precision precision) {
  switch (precision) {
    case Precision::float32:
      return kFloat32RelativeTolerance;
    case Precision::bfloat16:
    case Precision::float16:
      return kHalfPrecisionRelativeTolerance;
    case Precision::float64:
      break;
  }
  return kRelativeTolerance;
}

int checked_cases(long long cases, const Spelling& spelling) {
  if (cases < 1)
    throw InvalidArgument(spelling.option("cases") + " must be at least 1, got " +
                          std::to_string(cases));
  if (cases > kMaxCases) {
    throw InvalidArgument(spelling.with_value("cases", std::to_string(cases), false) +
                          " is above the bound " + std::to_string(kMaxCases) +
                          " (10^7 cases already take hours per cell through a plug-in)");
  }
  return static_cast<int>(cases);
}

int cases_to_detect(double frequency, const Spelling& spelling) {
  if (!(frequency > 0.0 && frequency < 1.0)) {
    throw InvalidArgument(spelling.with_value("detect", format_shortest(frequency), false) +
                          " is not a frequency in (0, 1); e.g. 0.01: a breaking on 1% of the "
                          "(scene, g) draws is found with 99% probability");
  }
  // n draws miss a breaking of frequency f with probability (1 - f)^n <= 0.01. The 1e-9 keeps
  // an exact quotient (f = 0.99: 1 draw) from rounding up to the next count.
  const double needed = std::ceil(std::log(0.01) / std::log1p(-frequency) - 1e-9);
  if (!(needed <= static_cast<double>(kMaxCases))) {
    throw InvalidArgument(spelling.with_value("detect", format_shortest(frequency), false) +
                          " needs " + format_fixed(needed, 0) + " cases, above the bound " +
                          std::to_string(kMaxCases) + "; ask for a larger frequency");
  }
  return std::max(1, static_cast<int>(needed));
}

double audit_relative_tolerance(const AuditOptions& options) {
  const double relative = options.relative_tolerance;
  if (!(relative >= 0.0 && relative < 1.0)) {
    throw InvalidArgument(options.spelling.option("tolerance") +
                          " must be a number in (0, 1), got " + format_number(relative) +
                          "; e.g. 1e-6, or a lower precision");
  }
  if (relative > 0.0) return relative;
  return precision_relative_tolerance(options.precision);
}

ClassifierOptions classifier_options(const AuditOptions& options) {
  (void)checked_cases(options.cases, options.spelling);
  if (options.views.empty() || options.groups.empty()) {
    throw InvalidArgument("an audit needs at least one view and one group");
  }
  ClassifierOptions classifier;
  classifier.groups = options.groups;
  classifier.views = options.views;
  classifier.check.cases = options.cases;
  classifier.precision_advice = [spelling = options.spelling](const std::string& precision) {
    return (spelling.command_line ? "rerun with " : "pass ") +
           spelling.with_value("precision", precision);
  };
  classifier.check.seed = options.seed;
  // One seed for everything the audit draws: the cases, a policy's noise per case, the laws'.
  classifier.check.noise_seed = options.seed;
  classifier.law_from_pointwise = !options.test_law;
  classifier.check.relative_tolerance = audit_relative_tolerance(options);
  classifier.check.unit_roundoff = probe_unit_roundoff(options.precision);
  classifier.check.output_unit_roundoff = unit_roundoff(options.precision);
  classifier.distribution.cases = std::max(10, (options.cases + 99) / 100);
  classifier.injectivity_cases = std::max(100, options.cases / 5);
  if (options.workspace) options.workspace->validate();
  classifier.check.shape.workspace = options.workspace;
  if (options.observations) {
    options.observations->validate();
    if (options.workspace) options.observations->require_inside(*options.workspace);
    classifier.check.shape.recorded = options.observations;
  }
  return classifier;
}

namespace {

// The command line asks single observations of one hand: an episode index (read by the closed
// loop) or one history per hand (read with hands=) would be silently misread; both are Python's.
void require_single_calls(const RecordedObservations& data) {
  if (!data.episode.empty())
    throw InvalidArgument("the observations of " + data.source +
                          " carry an 'episode' index, which only the closed loop of "
                          "handcentric.audit_policy(..., episodes=N) replays: leave 'episode' out "
                          "here");
  if (!data.hands().empty())
    throw InvalidArgument("the observations of " + data.source +
                          " record one history per hand, which handcentric.audit_policy(..., "
                          "hands=...) reads: record one history here");
}

// A plug-in's declared extra poses and scalars must be in recorded observations: the pipe would
// otherwise fill the missing ones with placeholders the data never had.
void require_recorded_names(const AuditOptions& audit, const PluginCapabilities& capabilities) {
  if (!audit.observations) return;
  require_single_calls(*audit.observations);
  const Scene& first = audit.observations->scenes.front();
  auto has = [](const auto& named, const std::string& name) {
    return std::any_of(named.begin(), named.end(), [&](const auto& n) { return n.first == name; });
  };
  for (const std::string& name : capabilities.extra_pose_names) {
    if (!has(first.extra_poses, name))
      throw InvalidArgument("the plug-in asks for extra pose '" + name +
                            "', which the observations of " + audit.observations->source +
                            " do not record: add it under \"extra_poses\"");
  }
  for (const std::string& name : capabilities.scalar_names) {
    if (!has(first.scalars, name))
      throw InvalidArgument("the plug-in asks for scalar '" + name +
                            "', which the observations of " + audit.observations->source +
                            " do not record: add it under \"scalars\"");
  }
}

}  // namespace

ClassifierOptions plugin_classifier_options(const AuditOptions& options,
                                            const PluginCapabilities& capabilities) {
  require_recorded_names(options, capabilities);
  ClassifierOptions classifier = classifier_options(options);
  classifier.check.shape.extra_pose_names = capabilities.extra_pose_names;
  classifier.check.shape.scalar_names = capabilities.scalar_names;
  // Prefetch passes gather each check's questions so that they go in batched requests.
  classifier.check.prefetch = capabilities.batch > 0;
  return classifier;
}

std::vector<Classification> audit_builtins(const std::vector<std::string>& names,
                                           const AuditOptions& options) {
  if (options.observations) require_single_calls(*options.observations);
  const ClassifierOptions classifier = classifier_options(options);
  const std::vector<std::string> all = auditable_names();
  std::vector<Classification> out;
  for (const std::string& name : names.empty() ? all : names) {
    if (name == "actionflow") {
      out.push_back(classify_flow_target(std::make_shared<ActionFlowTarget>(), classifier));
    } else if (std::find(all.begin(), all.end(), name) != all.end()) {
      out.push_back(classify_representation(make_representation(name), classifier));
    } else {
      std::string valid;
      for (const std::string& n : all) valid += (valid.empty() ? "" : ", ") + n;
      throw InvalidArgument("unknown representation '" + name + "' for --repr; use one of " +
                            valid + " (or --exec 'COMMAND' for your own)");
    }
  }
  return out;
}

void print_audit(std::ostream& out, const std::vector<Classification>& classifications,
                 const AuditOptions& options, bool witnesses) {
  constexpr std::size_t kLabel = 30, kCell = 14;
  for (const Classification& classification : classifications) {
    out << classification.name << "\n";
    std::vector<const Verdict*> failing, noted;
    for (View view : options.views) {
      out << "  " << view_heading(view, options.observations != nullptr) << "\n  "
          << pad("component", kLabel);
      for (Group group : options.groups) out << " | " << pad(to_string(group), kCell);
      out << "\n";
      for (Mode mode : {Mode::pointwise, Mode::distribution, Mode::closed_loop}) {
        for (Component component :
             {Component::actions, Component::observation, Component::flow_input,
              Component::flow_target, Component::policy}) {
          bool any = false;
          std::string row = "  " + pad(row_label(component, mode), kLabel);
          for (Group group : options.groups) {
            const Verdict* verdict = find_verdict(classification, component, mode, group, view);
            if (verdict == nullptr) continue;
            any = true;
            row += " | " + pad(cell_text(*verdict), kCell);
            if (!verdict->invariant && verdict->witness) failing.push_back(verdict);
            // A law from its pointwise cell: one line below for all of them.
            if (!verdict->note.empty() && verdict->method != Method::from_pointwise)
              noted.push_back(verdict);
          }
          if (any) out << row << "\n";
        }
      }
    }
    for (const Verdict* verdict : noted) {
      // The workspace is said once, in the header: its note is left out of each cell's here.
      // So are the recorded observations'.
      std::string note = verdict->note;
      for (const std::string& shared :
           {options.workspace ? options.workspace->verdict_note() : std::string(),
            options.observations ? options.observations->verdict_note() : std::string()}) {
        if (!shared.empty() && note.rfind(shared, 0) == 0)
          note.erase(0, std::min(note.size(), shared.size() + 2));
      }
      if (!note.empty()) out << "  note: " << cell_name(*verdict) << ": " << note << "\n";
    }
    // One line for the "yes" cells decided (partly) by tests (marked ~): what they could miss.
    int tested_yes = 0;
    bool policy = false;
    double largest_shift = 0.0, largest_ratio = 0.0;
    for (const Verdict& verdict : classification.verdicts) {
      if (verdict.invariant && (verdict.detectable_shift || verdict.detectable_scale_ratio)) {
        ++tested_yes;
        policy = policy || verdict.component == Component::policy;
        largest_shift = std::max(largest_shift, verdict.detectable_shift.value_or(0.0));
        largest_ratio = std::max(largest_ratio, verdict.detectable_scale_ratio.value_or(0.0));
      }
    }
    if (tested_yes > 0) {
      const std::string shift = format_significant(largest_shift, 2);
      const std::string ratio = format_significant(largest_ratio, 3);
      out << "  note: " << tested_yes
          << " in-distribution 'yes' cell(s) (marked ~) were decided by tests, the output not "
             "being (wholly) affine in the noise: each finds, with 90% power, a mean shift of "
          << shift << " (Euclidean norm over the tested coordinates, in "
          << (policy ? "the chunk's units: m for positions, rotation-matrix entries for rotations"
                     : "the component's units")
          << ")";
      if (largest_ratio > 0.0) {
        out << " or a standard deviation changed by a factor " << ratio
            << " (either way) in one coordinate";
      }
      out << " (the largest over the cells; per cell in the JSON's detectable_shift and "
             "detectable_scale_ratio); smaller differences can hide\n";
    }
    // The laws taken from their pointwise cells (policy_audit.hpp), marked =.
    const auto derived =
        std::count_if(classification.verdicts.begin(), classification.verdicts.end(),
                      [](const Verdict& v) { return v.method == Method::from_pointwise; });
    if (derived > 0) {
      out << "  note: " << derived
          << " in-distribution 'yes' cell(s) (marked =) follow from their pointwise cell: the "
             "policy is a function of its inputs (the preflight) and each case drew its own "
             "noise, so its laws agree but on the share of draws the pointwise 'yes' could miss "
             "(below); no in-distribution test was run ("
          << options.spelling.option("test_law") << (options.spelling.command_line ? "" : "=True")
          << " runs them)\n";
    }
    // What the pointwise "yes" cells could have missed (verdict.hpp: detectable_frequency).
    int fewest_cases = 0;
    for (const Verdict& verdict : classification.verdicts) {
      if (verdict.invariant && verdict.mode == Mode::pointwise &&
          (fewest_cases == 0 || verdict.cases < fewest_cases))
        fewest_cases = verdict.cases;
    }
    if (fewest_cases > 0) {
      const std::string frequency = format_significant(detectable_frequency(fewest_cases), 2);
      out << "  note: a pointwise 'yes' on " << fewest_cases
          << " far cases finds, with 99% probability, a breaking that occurs in at least "
          << frequency
          << " of the (scene, g) draws (per cell in the JSON's detectable_frequency); rarer ones "
             "can hide\n";
    }
    if (classification.preflight && !classification.preflight->repeatable)
      out << "  no pointwise verdict: " << classification.preflight->note << "\n";
    if (const auto& injectivity = classification.injectivity) {
      if (injectivity->injective == false) {
        out << "  !!! NOT INJECTIVE";
        if (injectivity->collision->search == "resolution") {
          // Lost below a resolution (a tokenizer, voxels): name it in its unit, both units when
          // both lose information.
          out << " below "
              << format_resolution(*injectivity->resolution, injectivity->resolution_unit);
          const bool metres = injectivity->resolution_unit == "m";
          const std::optional<double>& other =
              metres ? injectivity->rotation_resolution : injectivity->translation_resolution;
          if (other && *other >= kSmallestLoss)
            out << " and " << format_resolution(*other, metres ? "rad" : "m");
          out << ": chunks that differ by less can collide (here " << injectivity->collision->change
              << " gave the same actions), so a policy trained on it cannot tell them apart.\n";
        } else {
          out << ": " << injectivity->how << ". Its invariances say nothing useful: a policy "
              << "trained on it cannot tell these chunks apart.\n";
        }
        out << indent(format_collision(*injectivity->collision), "      ");
      } else {
        out << "  injective: " << (injectivity->injective ? "yes" : "not decided") << " ("
            << injectivity->how << ")\n";
      }
    }
    if (witnesses) {
      for (const Verdict* verdict : failing) {
        out << "  witness: " << cell_name(*verdict) << " (seed " << verdict->seed
            << ", shrunk by RapidCheck; replay with the same --seed)\n"
            << indent(format_witness(*verdict->witness), "    ");
      }
    }
    out << "\n";
  }
}

}  // namespace handcentric::props
