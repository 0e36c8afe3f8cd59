#include "handcentric/experiments/table2.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <numbers>
#include <random>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/experiments/insert3d_key_points.hpp"
#include "handcentric/experiments/results_page.hpp"
#include "handcentric/experiments/wilson.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/slice_team.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/sim/insert3d/camera.hpp"
#include "handcentric/sim/insert3d/expert.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::experiments {

namespace insert3d = sim::insert3d;

sim::insert3d::RolloutOptions insert3d_rollout_options(const policy::PolicyConfig& config) {
  insert3d::RolloutOptions options;
  options.history = config.history_length;
  options.execute = std::min(config.execute, config.chunk_length);
  options.max_replans = (kMaxRolloutSteps + options.execute - 1) / options.execute;
  return options;
}

Insert3dCounts evaluate_insert3d(const ChunkPolicy& policy,
                                 const insert3d::SceneDistribution& distribution, int trials,
                                 std::uint64_t seed, const insert3d::RolloutOptions& options) {
  if (trials < 1) throw InvalidArgument("trials must be at least 1, got " + std::to_string(trials));
  options.validate();
  const insert3d::CollisionChecker checker;  // one per call: checkers are not thread-safe
  Insert3dCounts counts;
  const auto scenes = insert3d::sample_scenes(distribution, trials, seed);
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const insert3d::Rollout result =
        insert3d::rollout(policy, scenes[i], sim::stream_seed(seed, i), checker, options);
    ++counts.trials;
    counts.clipped += result.clipped;
    switch (result.outcome) {
      case sim::Outcome::success:
        ++counts.success;
        break;
      case sim::Outcome::collision:
        ++counts.collision;
        break;
      case sim::Outcome::timeout:
        ++counts.timeout;
        break;
      case sim::Outcome::invalid:
        ++counts.invalid;
        break;
    }
  }
  return counts;
}

std::vector<insert3d::Demo> insert3d_train_demos(int count, std::uint64_t seed) {
  if (count < 1) throw InvalidArgument("demos must be at least 1, got " + std::to_string(count));
  const int tried = count + count / 5 + 10;
  const insert3d::CollisionChecker checker;
  const auto scenes = insert3d::sample_scenes(insert3d::SceneDistribution::train(), tried, seed);
  insert3d::ExpertRun run = insert3d::expert_demos(scenes, seed, checker);
  if (static_cast<int>(run.demos.size()) < count) {
    throw InvalidArgument("the 3D expert solved " + std::to_string(run.demos.size()) + " of " +
                          std::to_string(tried) + " train scenes (seed " + std::to_string(seed) +
                          "), fewer than the " + std::to_string(count) +
                          " demos asked for: ask for fewer");
  }
  run.demos.resize(static_cast<std::size_t>(count));
  return std::move(run.demos);
}

void Perturbation::validate(const std::string& flag) const {
  if (copies < 0 || copies > 100) {
    throw InvalidArgument(flag + "-copies " + std::to_string(copies) +
                          " is out of range: use 0..100");
  }
  if (!(max_cm >= 0.0 && max_cm < 1e3) || !(max_deg >= 0.0 && max_deg <= 180.0)) {
    throw InvalidArgument(flag + "-cm " + format_shortest(max_cm) + ", " + flag + "-deg " +
                          format_shortest(max_deg) +
                          ": out of range: use [0, 1000) cm and [0, 180] deg");
  }
}

Perturbation insert3d_default_perturbation(policy::ObservationKind observation) {
  return {2, 0.15, observation == policy::ObservationKind::image ? 5.0 : 1.0};
}

std::vector<Scene> insert3d_training_data(const std::vector<insert3d::Demo>& demos, int H, int K,
                                          const Perturbation& perturbation, std::uint64_t seed) {
  perturbation.validate();
  const insert3d::BladeSlotGeometry geometry;
  std::mt19937_64 rng(sim::stream_seed(seed, 0x7e57));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double max_rad = perturbation.max_deg * std::numbers::pi / 180.0;
  std::vector<Scene> scenes;
  for (const insert3d::Demo& demo : demos) {
    const std::vector<Scene> own = insert3d::training_scenes(demo, H, K, geometry);
    scenes.insert(scenes.end(), own.begin(), own.end());
    for (int copy = 0; copy < perturbation.copies; ++copy) {
      for (Scene scene : own) {
        const Eigen::Vector3d dp(unit(rng), unit(rng), unit(rng));
        const Eigen::Vector3d dr(unit(rng), unit(rng), unit(rng));
        // hand_T_moved: a small rigid motion expressed in the hand's own frame.
        const RigidTransform hand_T_moved(Rotation::exp(max_rad * dr), perturbation.max_cm * dp);
        for (RigidTransform& world_T_hand : scene.world_T_hand_history)
          world_T_hand = world_T_hand * hand_T_moved;
        const auto corners =
            insert3d::opening_corners_in_hand(geometry, scene.world_T_hand0(), demo.world_T_slot);
        scene.hand_points.assign(corners.begin(), corners.end());
        scenes.push_back(std::move(scene));
      }
    }
  }
  return scenes;
}

void Table2Options::validate() const {
  if (demos < 1 || demos > 1000) {
    throw InvalidArgument("--demos " + std::to_string(demos) + " is out of range: use 1..1000");
  }
  if (trials < 1 || trials > 100000) {
    throw InvalidArgument("--trials " + std::to_string(trials) + " is out of range: use 1..100000");
  }
  if (jobs < 0)
    throw InvalidArgument("--jobs " + std::to_string(jobs) +
                          " is negative: use 0 (one per core) or more");
  if (steps < 0)
    throw InvalidArgument("--steps " + std::to_string(steps) +
                          " is negative: use 0 (automatic) or more");
  if (methods.empty()) throw InvalidArgument("table2: no method: give at least one representation");
  if (observations.empty())
    throw InvalidArgument("table2: no observation: give key_points, image or both");
  for (const std::string& method : methods) make_representation(method);  // names the valid ones
  perturbation.validate();
  image_perturbation.validate("--image-perturb");
  if (std::find(observations.begin(), observations.end(), policy::ObservationKind::image) !=
      observations.end()) {
    policy::PolicyConfig config;
    config.task = policy::kTaskInsert3d;
    image.apply(config);
    config.validate();
  }
}

namespace {

constexpr const char* kSetNames[3] = {"train", "ood", "random_se3"};

const Insert3dCounts& set_counts(const Table2Row& row, int set) {
  return set == 0 ? row.train : set == 1 ? row.ood : row.random_se3;
}

// "depth and surface normals, 32 x 24, 70 deg, encoder 8,16,16, flatten"
std::string image_summary(const policy::PolicyConfig& config) {
  const Insert3dImageChannels channels = insert3d_camera_of(config)->options().channels;
  std::ostringstream text;
  text << (channels == Insert3dImageChannels::normals ? "depth and surface normals"
           : channels == Insert3dImageChannels::rgbd  ? "colour and depth"
                                                      : "depth")
       << ", " << config.image_width << " x " << config.image_height << ", " << config.image_fov_deg
       << " deg" << (config.image_cameras == 2 ? ", 2 cameras" : "") << ", encoder "
       << config.encoder << ", " << policy::to_string(config.image_features);
  return text.str();
}

// `threads`: the image policy's training steps (the key-point policies train on one).
Table2Row run_method(const Table2Options& options, const std::string& method,
                     policy::ObservationKind observation, const std::vector<Scene>& scenes,
                     int threads) {
  policy::PolicyConfig config;
  config.task = policy::kTaskInsert3d;
  config.representation = method;
  config.steps = options.steps;
  config.observation = observation;
  const bool image = observation == policy::ObservationKind::image;
  std::shared_ptr<const Insert3dHandCamera> camera;
  if (image) camera = options.image.apply(config);
  const auto start = std::chrono::steady_clock::now();
  const auto model = std::make_shared<const policy::LearnedPolicy>(
      image ? policy::train_policy(config, scenes, options.seed, {}, 100, camera, threads)
            : policy::train_policy(config, with_slot_key_points(scenes), options.seed, {}, 100,
                                   nullptr, 1));
  const double train_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.save_models) {
    policy::save_model(
        *model,
        (std::filesystem::path(options.out) / table2_model_file(method, observation)).string());
  }
  const std::shared_ptr<const ChunkPolicy> policy = insert3d_model_policy(model);
  const ChunkPolicy& trained = *policy;
  const insert3d::RolloutOptions rollout_options = insert3d_rollout_options(model->config());
  Table2Row row;
  row.method = method;
  row.observation = observation;
  if (image) row.image = image_summary(model->config());
  row.train_seconds = train_seconds;
  row.demos = options.demos;
  row.seed = options.seed;
  row.steps = model->config().steps;
  row.perturbation = options.perturbation_for(observation);
  const std::uint64_t eval_seed = options.seed + 1;
  row.train = evaluate_insert3d(trained, insert3d::SceneDistribution::train(), options.trials,
                                eval_seed, rollout_options);
  row.ood = evaluate_insert3d(trained, insert3d::SceneDistribution::ood(), options.trials,
                              eval_seed, rollout_options);
  row.random_se3 = evaluate_insert3d(trained, insert3d::SceneDistribution::random_se3(),
                                     options.trials, eval_seed, rollout_options);
  return row;
}

std::string row_label(const Table2Row& row) {
  return row.observation == policy::ObservationKind::image ? row.method + " (image)" : row.method;
}

std::string rate_with_interval(const Insert3dCounts& counts) {
  const Interval ci = wilson_interval(counts.success, counts.trials);
  return format_fixed(counts.success_rate(), 2) + " [" + format_fixed(ci.lo, 2) + ", " +
         format_fixed(ci.hi, 2) + "]";
}

}  // namespace

std::string table2_model_file(const std::string& method, policy::ObservationKind observation) {
  return observation == policy::ObservationKind::image ? method + "_image.hcm" : method + ".hcm";
}

std::vector<Scene> table2_training_data(const Table2Options& options,
                                        const std::vector<insert3d::Demo>& demos,
                                        policy::ObservationKind observation) {
  const policy::PolicyConfig defaults;
  return insert3d_training_data(demos, defaults.history_length, defaults.chunk_length,
                                options.perturbation_for(observation), options.seed);
}

std::vector<Table2Row> run_table2(const Table2Options& options) {
  options.validate();
  std::filesystem::create_directories(options.out);
  const std::vector<insert3d::Demo> demos = insert3d_train_demos(options.demos, options.seed);
  // One set of training scenes per observation (their noise injections differ).
  std::vector<std::vector<Scene>> scenes;
  for (const policy::ObservationKind observation : options.observations)
    scenes.push_back(table2_training_data(options, demos, observation));
  if (!options.quiet) {
    std::cerr << "table2: " << demos.size() << " demos (" << scenes.front().size()
              << " training samples), " << options.methods.size() << " methods x "
              << options.observations.size() << " observations, " << options.trials
              << " trials per scene set\n";
  }
  // Rows in order: every method for the first observation, then for the next.
  const std::size_t count = options.methods.size() * options.observations.size();
  std::vector<Table2Row> rows(count);
  std::vector<std::exception_ptr> errors(count);
  std::mutex print;
  const auto run_row = [&](std::size_t m, int threads) {
    try {
      const std::size_t o = m / options.methods.size();
      rows[m] = run_method(options, options.methods[m % options.methods.size()],
                           options.observations[o], scenes[o], threads);
      if (!options.quiet) {
        const std::lock_guard<std::mutex> lock(print);
        std::cerr << "table2: " << row_label(rows[m]) << " (trained in "
                  << static_cast<long>(rows[m].train_seconds) << " s) train "
                  << rows[m].train.success_rate() << " ood " << rows[m].ood.success_rate()
                  << " random-se3 " << rows[m].random_se3.success_rate() << "\n";
      }
    } catch (...) {
      errors[m] = std::current_exception();
    }
  };
  const auto image_row = [&](std::size_t m) {
    return options.observations[m / options.methods.size()] == policy::ObservationKind::image;
  };
  const int hardware = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int jobs = options.jobs > 0 ? options.jobs : hardware;
  // An image row's training runs its steps on `jobs` threads (SliceTeam), one row at a time: a
  // step's slices keep every core busy to the end, where rows side by side would leave one idle
  // while the last row trains alone. Key-point rows train on one thread each, `jobs` at a time.
  for (std::size_t m = 0; m < count; ++m) {
    if (image_row(m)) run_row(m, std::min(jobs, policy::SliceTeam::kMaxThreads));
  }
  std::vector<std::size_t> key_point_rows;
  for (std::size_t m = 0; m < count; ++m) {
    if (!image_row(m)) key_point_rows.push_back(m);
  }
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t k = next++; k < key_point_rows.size(); k = next++)
      run_row(key_point_rows[k], 1);
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < std::min<int>(jobs, static_cast<int>(key_point_rows.size())); ++j)
    threads.emplace_back(worker);
  worker();
  for (std::thread& thread : threads) thread.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
  const std::filesystem::path dir(options.out);
  write_file_atomically((dir / "table2.json").string(), table2_json(rows) + "\n");
  write_file_atomically((dir / "table2.md").string(), table2_markdown(rows));
  write_chart(table2_chart(rows), (dir / "table2").string());
  return rows;
}

std::string table2_json(const std::vector<Table2Row>& rows) {
  nlohmann::json out = {{"task", "insert3d"}, {"rows", nlohmann::json::array()}};
  for (const Table2Row& row : rows) {
    nlohmann::json r = {{"method", row.method},
                        {"observation", policy::to_string(row.observation)},
                        {"head", "flow"},
                        {"demos", row.demos},
                        {"trials", row.train.trials},
                        {"seed", row.seed},
                        {"eval_seed", row.seed + 1},
                        {"steps", row.steps},
                        {"train_seconds", row.train_seconds},
                        {"perturbation",
                         {{"copies", row.perturbation.copies},
                          {"max_cm", row.perturbation.max_cm},
                          {"max_deg", row.perturbation.max_deg}}}};
    if (!row.image.empty()) r["image"] = row.image;
    for (int set = 0; set < 3; ++set) {
      const Insert3dCounts& c = set_counts(row, set);
      const Interval ci = wilson_interval(c.success, c.trials);
      const std::string name = kSetNames[set];
      r[name + "_success"] = c.success_rate();
      r[name + "_wilson95"] = {ci.lo, ci.hi};
      r[name + "_counts"] = {{"success", c.success},
                             {"collision", c.collision},
                             {"timeout", c.timeout},
                             {"invalid", c.invalid},
                             {"clipped", c.clipped}};
    }
    out["rows"].push_back(r);
  }
  return out.dump(2);
}

std::string table2_markdown(const std::vector<Table2Row>& rows) {
  std::ostringstream md;
  md << "# Table 2 (3D blade insertion), simulated\n\n";
  if (!rows.empty()) {
    md << "Flow policies trained on " << rows.front().demos
       << " expert demos of train scenes (seed " << rows.front().seed << "), each evaluated on "
       << rows.front().train.trials << " closed-loop rollouts per scene set (scenes of seed "
       << rows.front().seed + 1
       << "; ood and random-se3 scene i is a global transform of train scene i). Success rate "
          "[Wilson 95%].\n\n";
  }
  // The noise injection of each kind of row, once per kind.
  for (const policy::ObservationKind kind :
       {policy::ObservationKind::key_points, policy::ObservationKind::image}) {
    const auto row = std::find_if(rows.begin(), rows.end(),
                                  [kind](const Table2Row& r) { return r.observation == kind; });
    if (row == rows.end()) continue;
    md << (kind == policy::ObservationKind::image ? "Image rows" : "Key-point rows")
       << " train on the demos' scenes";
    if (row->perturbation.copies > 0) {
      md << " and " << row->perturbation.copies
         << " noise-injected copies of each (the hand moved by up to " << row->perturbation.max_cm
         << " cm and turned by up to " << row->perturbation.max_deg
         << " deg per axis, in its own frame)";
    }
    md << ".\n\n";
  }
  for (const Table2Row& row : rows) {
    if (row.observation != policy::ObservationKind::image) continue;
    md << "Rows marked (image) see no key points: "
       << (row.image.find("2 cameras") != std::string::npos
               ? "the images of two cameras on the hand ("
               : "the hand camera's image (")
       << row.image
       << ") through a small CNN trained end to end with the flow head "
          "(experiments/insert3d_image.hpp).\n\n";
    break;
  }
  md << "| method | demos | steps | train | ood (slot on its side) | random-se3 |\n";
  md << "|---|---|---|---|---|---|\n";
  for (const Table2Row& row : rows) {
    md << "| flow / " << row_label(row) << " | " << row.demos << " | " << row.steps << " | "
       << rate_with_interval(row.train) << " | " << rate_with_interval(row.ood) << " | "
       << rate_with_interval(row.random_se3) << " |\n";
  }
  md << "\nThe paper's Table 2 for reference (a real robot, blade insertion, 35 trials; not "
        "rerunnable here):\n\n"
        "| method | in distribution | out of distribution (horizontal stacks) |\n"
        "|---|---|---|\n"
        "| hand-centric (paper) | 26/30 (0.87) | 5/5 (1.00) |\n";
  return md.str();
}

BarChart table2_chart(const std::vector<Table2Row>& rows) {
  if (rows.empty()) throw InvalidArgument("draw_table2: no rows to draw");
  BarChart chart;
  chart.title = "Table 2 analogue (sim, 3D blade insertion): success";
  chart.series = {"train", "ood", "random-se3"};
  chart.reference_label = "the paper (real robot)";
  for (const Table2Row& row : rows) {
    chart.groups.push_back("flow\n" + row_label(row));
    std::vector<std::optional<ChartValue>> values;
    for (int set = 0; set < 3; ++set) {
      const Insert3dCounts& c = set_counts(row, set);
      if (c.trials < 1) {
        values.emplace_back(std::nullopt);
        continue;
      }
      values.emplace_back(ChartValue{c.success_rate(), wilson_interval(c.success, c.trials)});
    }
    chart.values.push_back(values);
    // The paper has a hand-centric row only: 26/30 in distribution, 5/5 out of it.
    std::vector<std::optional<double>> reference(3);
    if (row.method == "hand_centric") {
      reference[0] =
          static_cast<double>(kPaperTable2InDistribution[0]) / kPaperTable2InDistribution[1];
      reference[1] =
          static_cast<double>(kPaperTable2OutOfDistribution[0]) / kPaperTable2OutOfDistribution[1];
    }
    chart.reference.push_back(reference);
  }
  chart.notes = {"bars: Wilson 95% intervals", "paper: ood = horizontal stacks"};
  return chart;
}

sim::Image draw_table2(const std::vector<Table2Row>& rows, int width, int height) {
  return render_chart(table2_chart(rows), width, height);
}

}  // namespace handcentric::experiments
