// `handcentric audit`: which global transforms leave each representation's actions,
// observation, flow input and flow target invariant, pointwise and in distribution, in the
// eye-in-hand and third-person views, with a shrunk witness for every cell that fails; or which
// transforms a whole policy is equivariant under (eq. 4) (docs/AUDIT.md).
//
//   handcentric audit                               every built-in and ActionFlow's target
//   handcentric audit --repr hand_centric --group se3 --cases 5000 --seed 7
//   handcentric audit --exec 'python3 examples/python_representation/repr.py' --json
//   handcentric audit --policy-exec 'python3 my_policy.py' --expect se3
//   handcentric audit --model hc.model
//   handcentric audit --model image.model --floor   # the hand camera sees the table too
//   handcentric audit --model hc.model --locate --group se3   # the first layer that breaks
//   handcentric audit --policy-exec 'python3 p.py' --locate   # the first stage that breaks
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "audit_profile.hpp"
#include "commands.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/flow_target.hpp"
#include "handcentric/experiments/audit_report_file.hpp"
#include "handcentric/experiments/model_audit.hpp"
#include "handcentric/experiments/model_locate.hpp"
#include "handcentric/experiments/plugin_locate.hpp"
#include "handcentric/experiments/witness_panel.hpp"
#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/audit_header.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/gate.hpp"
#include "handcentric/props/plugin_audit.hpp"
#include "handcentric/sim/image.hpp"

namespace handcentric::apps {
namespace {

struct AuditCommandOptions {
  std::vector<std::string> representations;
  // One or more names each, or "all" (props::parse_groups, props::parse_views).
  std::vector<std::string> groups = {"all"};
  std::vector<std::string> views = {"all"};
  long long cases = props::kDefaultCases;  // wide: a value past the bound is named, not wrapped
  double detect = 0.0;                     // --detect, when detect_given
  bool detect_given = false;
  int episodes = 0;  // --episodes: the closed loop of a --policy-exec plug-in (0: none)
  int episode_length = props::ClosedLoopOptions{}.steps;
  bool episode_length_given = false;
  bool page_given = false;  // --page, even with an empty folder (refused by write_audit_page)
  std::uint64_t seed = props::AuditOptions{}.seed;
  double timeout = props::kDefaultPluginTimeout;
  double tolerance = 0.0;
  std::string precision = "float64";
  std::string workspace, witness_dir, observations, page;
  bool json = false;
  bool pointwise = false;
  bool test_law = false;
  bool floor = false;
  bool locate = false;  // --locate (model_locate.hpp, plugin_locate.hpp)
  std::string exec, policy_exec, model;
  std::vector<std::string> extra_poses, scalars, expect;
  std::string profile, out;  // --profile GROUP --out DIR (audit_profile.hpp)
  int profile_scenes = props::ProfileOptions{}.scenes;
  std::vector<double> profile_sizes;
};

ProfileCommand profile_command(const AuditCommandOptions& options) {
  if (!options.workspace.empty() || !options.witness_dir.empty() || !options.expect.empty() ||
      !options.extra_poses.empty() || !options.scalars.empty() || !options.observations.empty())
    throw InvalidArgument(
        "--profile draws g by its size and writes --out; leave out --workspace, --witness-dir, "
        "--expect, --extra-poses, --scalars and --observations");
  return {options.profile,        options.views,         options.out,    options.representations,
          options.exec,           options.policy_exec,   options.model,  options.seed,
          options.profile_scenes, options.profile_sizes, options.timeout};
}

// --witness-dir: for each failing check of a policy that sees cameras, the images it was shown
// of the witness's o and of g o (what the policy saw differ), one PNG per camera and side.
void write_witness_images(const std::string& dir, const props::Classification& result,
                          const props::CameraRig& rig) {
  std::filesystem::create_directories(dir);
  int written = 0;
  for (const props::Verdict& verdict : result.verdicts) {
    if (!verdict.witness) continue;
    const std::string stem =
        dir + "/" + (result.output ? result.output->name + "_" : std::string()) +
        props::to_string(verdict.component) + "_" + props::to_string(verdict.group) + "_" +
        props::to_string(verdict.mode) + "_" + props::to_string(verdict.view) + "_";
    const Scene& o = verdict.witness->scene;
    const Scene moved = verdict.witness->g * o;
    const std::vector<CameraImage> before = props::render_views(o, rig);
    const std::vector<CameraImage> after = props::render_views(moved, rig);
    for (std::size_t v = 0; v < rig.views.size(); ++v) {
      const std::string camera = props::to_string(rig.views[v]);
      sim::write_png(stem + camera + "_o.png",
                     experiments::witness_panel(before[v], rig.camera.max_range));
      sim::write_png(stem + camera + "_g_o.png",
                     experiments::witness_panel(after[v], rig.camera.max_range));
      written += 2;
    }
  }
  std::cerr << "handcentric audit: " << written << " witness images in " << dir
            << " (colour beside depth, of o and of g o)\n";
}

// The gate (props/gate.hpp): each expected symmetry that does not hold, with its witness, on
// stderr, and exit 1.
int gate(const std::vector<props::Classification>& results,
         const std::vector<props::ExpectedSymmetry>& expectations) {
  const std::vector<props::GateFailure> failures = props::gate_failures(results, expectations);
  for (const props::GateFailure& failure : failures)
    std::cerr << "handcentric audit: " << props::gate_failure_text(failure);
  return failures.empty() ? 0 : 1;
}

// --locate: refused in one line, naming the fix, with what it cannot honour.
void check_locate_options(const AuditCommandOptions& options) {
  if (options.model.empty() && options.policy_exec.empty()) {
    throw InvalidArgument(
        "--locate looks inside a trained model of this library or a plug-in's declared stages: "
        "give --model FILE or --policy-exec COMMAND (a Python policy: handcentric.locate, "
        "docs/AUDIT.md \"Localizing a break\")");
  }
  const std::pair<bool, const char*> unhonoured[] = {
      {!options.expect.empty(), "--expect (a gate: run it without --locate)"},
      {!options.witness_dir.empty(), "--witness-dir (the witness is printed)"},
      {options.page_given, "--page (locate prints its own table)"},
      {options.test_law, "--test-law (locate asks pointwise cases only)"},
      {options.pointwise, "--pointwise (locate is pointwise already)"},
      {options.episodes > 0, "--episodes (locate asks single calls)"},
      {!options.model.empty() && (!options.extra_poses.empty() || !options.scalars.empty()),
       "--extra-poses and --scalars (a model reads neither)"}};
  for (const auto& [given, flag] : unhonoured) {
    if (given)
      throw InvalidArgument(std::string("--locate cannot honour ") + flag + ": leave it out");
  }
}

// --model M --locate, --policy-exec CMD --locate: one table per group (a plug-in's: per view and
// group), or one JSON document; exit 0 whatever it finds.
int run_locate(const AuditCommandOptions& options, props::AuditOptions& audit, bool named_groups) {
  const std::vector<experiments::ModelLocation> located =
      options.model.empty()
          ? experiments::locate_plugin(
                options.policy_exec, audit,
                props::PluginAuditSetup{options.timeout, options.extra_poses, options.scalars, {}})
          : experiments::locate_model(options.model, options.model, audit, named_groups,
                                      options.floor);
  if (options.json) {
    std::cout << experiments::locate_json(located);
    return 0;
  }
  for (std::size_t i = 0; i < located.size(); ++i)
    std::cout << (i ? "\n" : "") << experiments::locate_text(located[i]);
  return 0;
}

int run_audit(const AuditCommandOptions& options) {
  if (options.locate) check_locate_options(options);
  if (options.page_given && options.page.empty())  // before the audit, not after it
    throw InvalidArgument("--page needs a folder, e.g. --page audit_page");
  // CLI11 refuses --test-law beside --repr or --exec; with no source at all the audit is the
  // built-ins', representations too.
  if (options.test_law && options.policy_exec.empty() && options.model.empty()) {
    throw InvalidArgument(
        "--test-law is for a whole policy (--policy-exec COMMAND or --model FILE): the "
        "built-in representations' laws are always tested; leave --test-law out");
  }
  props::AuditOptions audit;
  audit.groups = props::parse_groups(options.groups, "group");
  audit.views = props::parse_views(options.views, "view");
  // "all" (the default), as against groups and views named one by one.
  auto has_all = [](const std::vector<std::string>& names) {
    return std::find(names.begin(), names.end(), "all") != names.end();
  };
  const bool all_groups = has_all(options.groups), all_views = has_all(options.views);
  audit.cases = props::checked_cases(options.cases);  // 1 to props::kMaxCases
  if (options.detect_given) {
    audit.cases = props::cases_to_detect(options.detect);
    audit.detect = options.detect;
  }
  audit.seed = options.seed;
  audit.test_law = options.test_law;
  audit.precision = props::parse_precision(options.precision);
  audit.relative_tolerance = options.tolerance;
  if (!options.workspace.empty()) audit.workspace = props::Workspace::parse(options.workspace);
  if (!options.observations.empty()) {
    audit.observations = std::make_shared<props::RecordedObservations>(
        props::read_observations(options.observations));
    // Data without world points show the third-person view nothing to move: one view only.
    if (all_views && !audit.observations->has_world_points())
      audit.views = {props::View::eye_in_hand};
  }
  (void)props::audit_relative_tolerance(audit);  // validates --tolerance before anything runs
  if (options.locate) return run_locate(options, audit, !all_groups);
  const std::vector<props::ExpectedSymmetry> expectations =
      props::parse_expectations(options.expect);
  const bool plugin_names = !options.extra_poses.empty() || !options.scalars.empty();
  props::PluginAuditSetup plugin{options.timeout, options.extra_poses, options.scalars, {}};
  if (options.episodes > 0) {
    audit.closed_loop = true;  // recorded episodes (an 'episode' index) are then replayed
    if (options.episode_length_given && audit.observations &&
        !audit.observations->episode.empty()) {
      throw InvalidArgument("--episode-length " + std::to_string(options.episode_length) +
                            " with recorded episodes: each is replayed as long as recorded; "
                            "leave --episode-length out");
    }
    plugin.closed_loop = props::ClosedLoopOptions{};
    plugin.closed_loop->episodes = options.episodes;
    plugin.closed_loop->steps = options.episode_length;
  }
  std::vector<props::Classification> results;
  std::optional<props::PolicyInterface> interface;  // a policy plug-in's
  bool policies = false, planar_model = false;
  if (!options.exec.empty()) {
    results.push_back(props::audit_representation_plugin(options.exec, audit, plugin));
  } else if (!options.policy_exec.empty()) {
    const props::PolicyPluginAudit audited =
        props::audit_policy_plugin(options.policy_exec, audit, plugin);
    results = audited.results;
    interface = audited.interface;
    policies = true;
    if (!options.witness_dir.empty()) {
      if (!audited.cameras) {
        throw InvalidArgument(
            "--witness-dir saves the images of a failing check, but the plug-in's "
            "hello declares no \"cameras\"; declare them, or leave --witness-dir "
            "out");
      }
      for (const props::Classification& result : results)
        write_witness_images(options.witness_dir, result, *audited.cameras);
    }
  } else if (!options.model.empty()) {
    if (plugin_names)
      throw InvalidArgument("--extra-poses and --scalars are for plug-ins; a model reads neither");
    const experiments::ModelAudit audited = experiments::audit_model(
        options.model, options.model, audit, !all_groups, options.pointwise, options.floor);
    results.push_back(audited.result);
    planar_model = audited.planar;
    policies = true;
  } else {
    if (plugin_names)
      throw InvalidArgument(
          "--extra-poses and --scalars are for plug-ins; the built-ins read neither");
    results = props::audit_builtins(options.representations, audit);
  }
  std::ostringstream header;  // the lines above the tables, on the page too
  props::print_audit_header(header, audit, policies);
  if (interface && !props::describe(*interface).empty())
    header << props::describe(*interface) << "\n";
  if (options.page_given) {
    experiments::write_audit_page(options.page, results, audit, header.str());
    std::cerr << "handcentric audit: wrote " << options.page << "/index.html and index.md\n";
  }
  if (options.json) {
    std::cout << (policies ? props::policy_audit_json(results, interface ? &*interface : nullptr)
                           : props::audit_json(results));
    return gate(results, expectations);
  }
  std::cout << header.str();
  props::print_audit(std::cout, results, audit);
  if (planar_model && all_groups) std::cout << "\n" << experiments::kPlanarModelNote << "\n";
  return gate(results, expectations);
}

}  // namespace

void add_audit_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<AuditCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "audit", "which global transforms each representation is invariant under, and why not");
  auto* repr = cmd->add_option(
      "--repr", options->representations,
      "a built-in to audit (absolute, relative, relative_diff, hand_centric, actionflow); "
      "repeatable; default: all");
  cmd->add_option("--group", options->groups,
                  "one or more of translation, rotation, se2, se3, c8, or all, e.g. --group "
                  "rotation se3")
      ->capture_default_str();
  cmd->add_option("--view", options->views,
                  "one or both of eye_in_hand (no world points: Theorem 1's setting) and "
                  "third_person (1-8 world points that move with g), or all")
      ->capture_default_str();
  auto* cases = cmd->add_option("--cases", options->cases,
                                "cases per pointwise check, at most 10^7 (in distribution: max(10, "
                                "cases/100))")
                    ->capture_default_str();
  auto* detect = cmd->add_option(
      "--detect", options->detect,
      "FREQUENCY: instead of --cases, as many cases as find a breaking on that share of the "
      "(scene, g) draws with 99% probability, e.g. 0.01 (459 cases; the default 1000 finds "
      "0.0046)");
  detect->excludes(cases);
  cmd->add_option("--seed", options->seed,
                  "seeds all the audit draws (the cases, a policy's fixed noise, the "
                  "in-distribution draws): the same seed gives the same verdicts and witnesses")
      ->capture_default_str();
  cmd->add_option("--tolerance", options->tolerance,
                  "REL in the pointwise tolerance REL * (1 + L); default 1e-9 (float64 rounding)");
  cmd->add_option("--precision", options->precision,
                  "the arithmetic the map is computed in: float64, float32 (REL = 3.8e-6), "
                  "bfloat16 or float16 (REL = 2^-7)")
      ->capture_default_str();
  cmd->add_option("--witness-dir", options->witness_dir,
                  "with --policy-exec and a plug-in that sees cameras: save the images of each "
                  "failing check's o and g o as PNGs in this folder");
  cmd->add_option("--observations", options->observations,
                  "FILE.jsonl or FILE.npz: draw every scene from your own recorded observations "
                  "(world-frame poses and points that move with g; hand points, scalars and "
                  "held arrays such as images that do not; docs/AUDIT.md)");
  cmd->add_option("--workspace", options->workspace,
                  "x0,y0,z0,x1,y1,z1 (m): draw every scene inside this box and every g so that "
                  "g * scene stays in it (a policy meant for its cell); default: anywhere");
  cmd->add_option("--timeout", options->timeout, "seconds to wait for each answer of a plug-in")
      ->capture_default_str();
  cmd->add_option(
         "--extra-poses", options->extra_poses,
         "names of world-frame poses to send a plug-in (they move with g), e.g. start,left_hand; "
         "a plug-in can also ask for them in its hello")
      ->delimiter(',');
  cmd->add_option(
         "--scalars", options->scalars,
         "names of numbers to send a plug-in (g leaves them alone), e.g. gripper; a plug-in can "
         "also ask for them in its hello")
      ->delimiter(',');
  cmd->add_option(
         "--expect", options->expect,
         "a gate: exit 1 with the witness unless every check under GROUP holds (COMPONENT:GROUP "
         "for one component), e.g. --expect se3 or --expect actions:se3,observation:translation")
      ->delimiter(',');
  auto* json = cmd->add_flag("--json", options->json,
                             "print the JSON document of docs/AUDIT.md instead of tables");
  auto* pointwise = cmd->add_flag(
      "--pointwise", options->pointwise,
      "--model only: the pointwise cells alone, no in-distribution ones (Table 1's audit)");
  auto* test_law = cmd->add_flag(
      "--test-law", options->test_law,
      "a whole policy: run the in-distribution tests on every cell, also where the pointwise "
      "check holds (by default such a cell's law follows from it: docs/AUDIT.md)");
  auto* exec =
      cmd->add_option("--exec", options->exec,
                      "audit a representation written in any language: COMMAND speaks JSON Lines "
                      "(docs/AUDIT.md)");
  auto* policy_exec =
      cmd->add_option("--policy-exec", options->policy_exec,
                      "audit a whole policy written in any language (eq. 4): COMMAND answers the "
                      "world chunk for an observation and a noise vector (docs/AUDIT.md)");
  auto* episodes = cmd->add_option(
      "--episodes", options->episodes,
      "with --policy-exec: also the closed loop, N episodes of two rollouts each (o_1..o_T and "
      "g o_1..g o_T, the first pose executed at every step), for a plug-in that keeps state "
      "between calls (its hello's \"episodes\": docs/AUDIT.md)");
  episodes->check(CLI::Range(1, props::kMaxCases));
  auto* episode_length = cmd->add_option("--episode-length", options->episode_length,
                                         "with --episodes: the steps T of each rollout, 1 to 10000")
                             ->check(CLI::Range(1, 10000))
                             ->capture_default_str()
                             ->needs(episodes);
  auto* model =
      cmd->add_option("--model", options->model, "audit a trained model of this library (eq. 4)");
  auto* floor = cmd->add_flag(
      "--floor", options->floor,
      "--model of an image policy of the 3D task: its hand camera also sees a table fixed in the "
      "world (z <= 0), which g does not move with the scene");
  cmd->add_flag("--locate", options->locate,
                "with --model: where the model breaks the symmetry, layer by layer (each "
                "layer's output invariant, the decoded chunk equivariant, on the audit's "
                "pointwise cases), the first layer that breaks with its witness; with "
                "--policy-exec: the same for the stages its hello declares, each by its kind "
                "(docs/AUDIT.md, \"Localizing a break\")");
  floor->needs(model);
  exec->excludes(repr)->excludes(policy_exec)->excludes(model);
  policy_exec->excludes(repr)->excludes(model);
  episodes->needs(policy_exec);
  model->excludes(repr);
  pointwise->needs(model);
  test_law->excludes(pointwise)->excludes(repr)->excludes(exec);
  auto* page = cmd->add_option(
      "--page", options->page,
      "also write the audit as a page into DIR: index.html and index.md (the header, one "
      "verdict grid per map, output and view, each NO cell linked to its witness and its "
      "picture)");
  auto* profile = cmd->add_option(
      "--profile", options->profile,
      "GROUP: how far from equivariant, the error against the size of g (rad, m or the C8 "
      "element) with its slope at the identity; writes DIR/profile.json and DIR/profile.png");
  auto* out = cmd->add_option("--out", options->out, "with --profile: the folder to write");
  cmd->add_option("--profile-scenes", options->profile_scenes,
                  "with --profile: scenes per size, 1 to 10^4")
      ->capture_default_str();
  cmd->add_option("--profile-sizes", options->profile_sizes,
                  "with --profile: the sizes of g, e.g. 0.01,0.1,1 (default: the group's grid)")
      ->delimiter(',');
  profile->needs(out)->excludes(json)->excludes(pointwise)->excludes(detect)->excludes(episodes);
  page->excludes(profile);
  out->needs(profile);
  cmd->callback([options, detect, episode_length, page, &exit_code] {
    options->page_given = page->count() > 0;
    options->detect_given = detect->count() > 0;
    options->episode_length_given = episode_length->count() > 0;
    if (options->locate && !options->profile.empty())
      throw InvalidArgument("--locate cannot honour --profile: run them one at a time");
    exit_code = options->profile.empty() ? run_audit(*options)
                                         : run_audit_profile(profile_command(*options));
  });
}

}  // namespace handcentric::apps
