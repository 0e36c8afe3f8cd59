#pragma once
// Table 1 (Sec. 4.2) end to end: nested demo sets made once, one cell per (method, head, demo
// count, training seed), each trained and scored on three scene sets (cell.hpp), then the table,
// its JSON and its figure. The same directory layout serves three ways of running:
//   run_table1      : every cell in this process, on `jobs` threads (one training per thread);
//   write_plan      : every unfinished cell as one shell line of `handcentric train` and
//                     `handcentric eval` in DIR/jobs.txt, for GNU parallel or a Slurm array;
//   collect_table1  : the table from whatever result files DIR holds.
//
//   DIR/demos-seed<S>.jsonl   the demos (the first N of them train an N-demo cell)
//   DIR/cells.json            the grid and the evaluation settings (what collect reads)
//   DIR/models/<hash>.hcm     trained models, named by cell_hash
//   DIR/results/<hash>.<set>-s<seed>-n<trials>.json   `handcentric eval --json` of each set
//   DIR/table1.json, table1.md, table1.png and table1.svg (plot.hpp)
// Every file is written to a temporary file and renamed, so a killed run leaves no half file
// and `resume` redoes only the missing models and results.
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/experiments/cell.hpp"
#include "handcentric/experiments/methods.hpp"
#include "handcentric/experiments/results.hpp"
#include "handcentric/sim/difficulty.hpp"

namespace handcentric::experiments {

/// Which training data every cell trains on (`handcentric table1 --protocol`).
///   library : this library's default, sim::TrainingData{}: the demos, their mirror images about
///             the hole axis and 4 perturbed recovery copies of every sample;
///   paper   : the demos alone, as the paper trains its policies (Sec. 4.2): no mirror images,
///             no recovery copies, so the automatic budget counts the demo samples only.
enum class Protocol { library, paper };
std::string to_string(Protocol protocol);
/// "library" or "paper"; throws InvalidArgument naming the text and both names.
Protocol parse_protocol(const std::string& text);
/// The training data recipe of `protocol` (perturbation_seed 1; each cell sets its own).
sim::TrainingData training_data(Protocol protocol);
/// One line saying what `data` trains on, naming its protocol when it is one of them (the
/// perturbation seed aside, which each cell sets to its training seed).
std::string describe_training_data(const sim::TrainingData& data);

struct Table1Options {
  std::vector<int> demo_counts = {kPaperDemoCounts.begin(), kPaperDemoCounts.end()};
  std::vector<Method> methods = table1_methods();
  std::vector<std::string> heads = {"flow"};
  std::uint64_t demo_seed = 1;
  std::vector<std::uint64_t> train_seeds = {1};
  EvalSettings eval;
  int steps = 0;  ///< Adam steps per cell; 0: the library's automatic budget (PolicyConfig)
  /// Every cell's training data recipe; training_data(Protocol::library) by default.
  sim::TrainingData data;
  /// The task's workspace and clearance, shared by the demos, the scenes and the checker
  /// (`--workspace`, `--clearance`; the paper's 100 cm and 0.1 cm by default).
  sim::Difficulty difficulty;
  int jobs = 0;  ///< trainings at once; 0: one per hardware thread
  std::string out = "table1";
  bool resume = false;
  bool quiet = false;

  /// Throws InvalidArgument naming the first bad value and the fix (a demo count outside
  /// 1..1000 or repeated, steps < 0, no method, no training seed, trials < 1, jobs < 0, ood_seed
  /// equal to eval_seed: the OOD set would be the paired one, a bad difficulty).
  void validate() const;
};

/// Comma-separated positive integers ("5,10,20"); throws InvalidArgument naming `option` and
/// the text.
std::vector<int> parse_int_list(const std::string& text, const std::string& option);
std::vector<std::uint64_t> parse_seed_list(const std::string& text, const std::string& option);

struct Table1Grid {
  std::string dir;        ///< options.out, absolute
  std::string demo_file;  ///< relative to dir
  sim::Difficulty difficulty;
  std::vector<Cell> cells;
};

/// Creates DIR, its demos (or reuses them when present; a non-default difficulty is in the demo
/// file's name) and DIR/cells.json. Without
/// options.resume a DIR that already holds cells.json is an error (pass --resume or another
/// --out). Throws InvalidArgument when the expert leaves too few demos.
Table1Grid prepare_table1(const Table1Options& options);

/// Trains and scores every cell whose files are missing, options.jobs at a time, with a progress
/// display on stderr. Cells that train the same bits (their heads have one policy::trained_as:
/// c8_averaged and c8_centre) are one training: the first trains, the others take its weights
/// (policy::with_head_kind), which is a third of the C8 rows' time. A failed cell stops the run
/// (the running cells finish) and is rethrown naming the cell.
void run_table1(const Table1Options& options, const Table1Grid& grid);

/// Writes DIR/jobs.txt: one line per cell with a missing result, `cli` train (unless its model
/// exists) then eval of each missing set, outputs renamed into place. Returns the line count.
/// Every line trains its own cell, so the lines stay independent: a c8_averaged line trains
/// c8_centre's network again, to the same bits (tests/experiments: the plan's models equal the
/// in-process ones).
int write_plan(const Table1Grid& grid, const EvalSettings& eval, const std::string& cli);

/// The rows from DIR/cells.json and whatever result files exist; writes DIR/table1.json,
/// table1.md, table1.png and table1.svg; returns the markdown (our table beside the paper's).
/// Throws InvalidArgument when DIR has no cells.json.
std::string collect_table1(const std::string& dir);

/// table1.md: the run's settings under the title (`training`, when not empty, says what every
/// cell trained on: collect_table1 passes describe_training_data of the cells' recipe when they
/// share one; a non-default `difficulty` is said too), then table1_table (results_page.hpp) of
/// `rows`, rendered by the report page's Markdown renderer.
std::string table1_markdown(const std::vector<Row>& rows, const EvalSettings& eval,
                            std::uint64_t demo_seed, const std::string& training = "",
                            const sim::Difficulty& difficulty = {});

}  // namespace handcentric::experiments
