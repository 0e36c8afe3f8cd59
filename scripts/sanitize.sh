#!/usr/bin/env bash
# The sanitizer run of CI: builds handcentric with clang 14, AddressSanitizer (with
# LeakSanitizer) and UndefinedBehaviorSanitizer into ${ASAN_BUILD_DIR:-build-asan} (-O1 with line
# tables, no benchmarks, the libFuzzer targets too, with coverage feedback on the parsers of
# outside data only: on every file it made the tests 1.5-2.8x slower; experiments/, apps/ and
# their tests uninstrumented at -O0, below), runs the ctest labels
# unit and proofs there and the numerics properties of label property, then every fuzz target
# for ${FUZZ_SECONDS:-10} s
# (scripts/fuzz.sh, same tree;
# 10 s in CI for its 25 minutes: the longer runs of docs/RELIABILITY.md, 60 s and 240 s per
# target, found nothing).
# A report aborts the test or fuzz run that caused it, so any report fails this script and CI.
# Prints the build, test and fuzz times last. docs/RELIABILITY.md has the measured figures.
#   bash scripts/sanitize.sh          # build, then tests and fuzzing
#   bash scripts/sanitize.sh build    # the build alone (scripts/test.sh runs it at nice 19
#                                     # beside the Release tests, on the CPU they leave idle)
#   bash scripts/sanitize.sh test     # tests and fuzzing on a tree already built
set -euo pipefail
step="${1:-all}"
case "$step" in
  all | build | test) ;;
  *) echo "sanitize.sh: unknown step '$step': use build, test or nothing (both)" >&2; exit 2 ;;
esac
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${ASAN_BUILD_DIR:-$root/build-asan}"
jobs="$(nproc 2>/dev/null || echo 2)"
cxx="${SANITIZE_CXX:-clang++}"
command -v "$cxx" >/dev/null || {
  echo "sanitize.sh: $cxx not found: bash scripts/install-deps.sh (clang, libfuzzer-14-dev)" >&2
  exit 2
}

# exitcode=23: a report must not pass for the exit status 1 that the command-line tests expect
# of a refused input (the sanitizers exit with 1 by default).
export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:exitcode=23
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1:exitcode=23
# Set before the build too: catch_discover_tests runs each test program to list its cases.
# print_suppressions=0: the summary of used suppressions would add lines to the one-line errors
# that the command-line tests check.
export LSAN_OPTIONS="suppressions=$root/tests/support/lsan.supp:print_suppressions=0"

# Uninstrumented at -O0 (cmake/HandcentricSanitize.cmake): the orchestration layer, the tables,
# reports and charts of experiments/, the command's front end in apps/ and their two test
# programs; a third of this tree's compile time at -O1 with the sanitizers, for code that parses
# no outside data of its own (the files it reads go through the libraries, instrumented here and
# fuzzed). Their tests still run here, on the instrumented libraries under them.
plain="handcentric_experiments;handcentric;test_experiments;test_conventions"

# Clang: libFuzzer needs it, and one tree then serves the tests and the fuzz targets.
start=$(date +%s)
if [ "$step" != test ]; then
  CXX="$cxx" cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_UNITY_BUILD=ON \
        -DHANDCENTRIC_SANITIZE=address,undefined -DHANDCENTRIC_FUZZ=ON \
        -DHANDCENTRIC_FUZZ_COVERAGE=parsers -DHANDCENTRIC_BUILD_BENCH=OFF \
        "-DHANDCENTRIC_SANITIZE_PLAIN=$plain" >/dev/null
  cmake --build "$build_dir" -j "$jobs"
fi
built=$(date +%s)
if [ "$step" = build ]; then
  echo "sanitize: build $((built - start)) s"
  exit 0
fi
[ -f "$build_dir/CMakeCache.txt" ] ||
  { echo "sanitize.sh: $build_dir is not built: bash scripts/sanitize.sh build first" >&2; exit 2; }

# Left out, for time (docs/RELIABILITY.md has the figures; the Release tree of CI runs all of it):
#  - the numerics properties run 1e4 cases each instead of 1e5 (RapidCheck's allocations under
#    ASan make a case ~100 times slower);
#  - policy_unit_suite_on_{generic,avx2}_kernels, the whole policy unit suite again on the other
#    kernel sets: test_kernels runs every kernel target and the whole Mlp on each;
#  - the end-to-end tests that run the `handcentric` command through whole trainings, audits,
#    tables or reports (and the report page's check in Chromium), or a Python plug-in (which runs
#    in the unsanitized interpreter): half of this run's time (the conventions' table alone, 13
#    plug-ins, runs for minutes under ASan). The library code they drive runs
#    under the sanitizers in the unit tests (the recorded observations' in test_recorded.cpp),
#    and the command's refusals of bad input (the short `*_cli_*` tests) stay in, but for the
#    one that needs a whole table's output (table1_cli_an_existing_run_needs_resume), and those of
#    `conventions --detect` that audit a layout through a plug-in (and their mutants);
#  - three statistical tests of the audit on random networks (the energy test's fallback, a
#    decoder that forgets R0, Theorem 1 pointwise and in law): 134 s under ASan; the same code
#    paths run in shorter tests of the run (the energy test's detectable shift, the world-delta
#    mode, the outer policy of any random network);
#  - the batched policy audits' comparisons with the unbatched ones, in process and through the
#    --exec pipe (whole audits each way, and planted batch-dependent maps): 240 s under ASan,
#    20 s in the Release tree; the batching code runs here in the batched representation
#    audit's comparison, the batched maps' refusals and the pipe's shorter batch tests;
#  - two audits of a whole toy table's models and of a float32 plug-in at three tolerances
#    (table1_audits_every_model..., float32_rounding_is_named...): 48 s under ASan; the audit
#    of a saved model runs here through the table2 and sim CLI audits, the float32 note in
#    float32_rounding_gets_a_note_and_passes_at_float32_tolerance;
#  - the two audits of every built-in against the paper's table (builtin_representations_are_...,
#    every_builtin_cell_matches_...): 25 s under ASan; the same classifier runs here in the
#    batched representation audit's comparison and the planted-fault audits;
#  - three more whole audits: six audits of one built-in through the command's several-name
#    --group and --view (audit_takes_several_groups_...), the image model's audit with the table
#    in view (sim_cli_audit_with_the_table_...), and the world-delta map in law on 50 seeds x 4
#    groups (the_world_delta_mode_is_never_called_...): 44 s under ASan; the flag parsing runs
#    here in the command's refusals, the image audit in the other sim_cli_audit tests, the exact
#    Gaussian test in the world-delta map's translation test; and six audits of a Python plug-in
#    that clips its positions (a_policy_clipping_world_positions_...: Python runs unsanitized;
#    the extra cases' paired draws run here in the in-distribution tests of test_policy_audit);
#  - seven more whole audits: a planted-fault encoder's whole classification
#    (mutant_encoder_is_classified_...; the classifier and its report run here in the other
#    planted-fault audits), a float32 policy's audits on several seeds
#    (a_float32_policy_leaking_...; the float32 path runs here in float32_rounding_gets_a_note_...)
#    and five audits of saved models through the command (table2_cli_saved_absolute_image_...,
#    the four policy_cli_audit_finds_the_c8_...): a saved model's audit runs here in
#    table2_cli_saved_hand_centric_image_model_is_se3_equivariant and the sim_cli_audit tests;
#  - the 300 mutated .npz files: their bound on the peak memory reads the RSS, which ASan's shadow
#    and quarantine inflate; the readers run here under the fuzz target fuzz_observations and in
#    the other .npz tests;
#  - three simulations of the in-distribution tests' power (the tabulated detectable shift, the
#    scale test on curved world noise and without the exact split): 196 s under ASan; the same
#    code paths run in the shorter anisotropic-noise and scale-test-level tests.
export HANDCENTRIC_NUMERIC_CASES=10000
end_to_end='^policy_unit_suite_on_|^policy_exec_audits_a_whole_policy|^expect_gates_exit_1|'\
'^table1_cli_in_process_plan|^policy_cli_train_defaults_to_the_automatic_budget|'\
'^table1_c8_cell_from_its_plan_line|^table1_plan_evaluates_in_the_runs|^table1_c8_averaged_shares|'\
'^audit_model_finds_a_trained|^protocol_v2_plugin_gets|'\
'^python_plugin_audit_matches|^main_report_opens_with|^outputs_are_whole_or_absent_after_sigkill|'\
'^report_page_writes_markdown_and_html|^report_page_check_in_chromium|'\
'^a_flow_not_affine_in_the_noise_falls_back|^a_policy_whose_decoder_forgets_R0|'\
'^any_network_inside_the_hand_centric_outer_policy|'\
'^the_tabulated_detectable_shift_is_the_simulated_one|'\
'^anisotropic_world_noise_through_a_curve|^without_the_exact_split_and_the_scale_test|'\
'^conventions_committed_table_is_up_to_date|^mutant_conventions_a_changed_formula|'\
'^mutant_conventions_a_base_that_stays_put|^mutant_conventions_detect_|'\
'^conventions_cli_detect_names_a_misdeclared|^conventions_cli_detect_flags_a_component_wise|'\
'^policy_exec_audits_a_plugin_on_recorded_observations|'\
'^a_batched_policy_audit_is_the_unbatched_one_bit|^a_map_whose_answer_depends_on_its_batch|'\
'^a_batched_exec_audit_gives_the_unbatched_json|^a_batched_policy_exec_audit_gives_the_unbatched|'\
'^table1_cli_writes_the_table_beside_the_papers|^table1_cli_an_existing_run_needs_resume|'\
'^table2_cli_image_rows_beside_the_key_point_rows|^table1_audits_every_model_and_shows|'\
'^float32_rounding_is_named_and_precision_float32|^a_plugin_that_draws_its_own_noise|'\
'^policy_exec_hands_a_plugin_the_images|^300_mutated_npz_files|'\
'^builtin_representations_are_classified_as_the_paper|^every_builtin_cell_matches_its_exp|'\
'^audit_takes_several_groups_and_views|^sim_cli_audit_with_the_table_in_view_loses_se3|'\
'^the_world_delta_mode_is_never_called_invariant|^a_policy_clipping_world_positions|'\
'^mutant_encoder_is_classified_translation_only|^a_float32_policy_leaking_0.6_mm_fails_on_every|'\
'^table2_cli_saved_absolute_image_model_is_not|^policy_cli_audit_finds_the_c8_'
# Of label property, the numerics properties only (1e4 cases of every geometry routine: edge
# inputs are where undefined behaviour hides). The others, properties of the checks, policies and
# tasks on many drawn cases, drive the library code that the unit tests drive here (163 s of
# the run under ASan, 2026-12-05); they run in the Release tree.
(cd "$build_dir" && ctest --output-on-failure -j "$jobs" -L 'unit|proofs' -E "$end_to_end")
(cd "$build_dir" && ctest --output-on-failure -j "$jobs" -L property -R '^numerics_')
tested=$(date +%s)

FUZZ_BUILD_DIR="$build_dir" FUZZ_CXX="$cxx" bash "$root/scripts/fuzz.sh" "${FUZZ_SECONDS:-10}"
fuzzed=$(date +%s)
echo "sanitize: build $((built - start)) s, tests $((tested - built)) s" \
     "(labels unit, proofs; the numerics properties)," \
     "fuzzing $((fuzzed - tested)) s"
