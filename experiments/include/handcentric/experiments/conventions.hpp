#pragma once
// The table of public pose conventions (docs/CONVENTIONS.md): each plug-in of a folder (this
// project's own code, conventions/, each citing in its docstring the codebase, file and formula
// it follows) audited through the --exec pipe with a fixed seed, and the verdicts written as one
// row per convention: per group, in the eye-in-hand and third-person views, the actions
// pointwise, the flow target in distribution and the observation pointwise, each NO linked to
// its witness; whether the map keeps the chunk's information (injectivity, resolution); and
// where each row comes from (the configurations using it, the commits read, its plug-in).
//
// The same results give the Markdown file (conventions_markdown, which a test keeps equal to
// docs/CONVENTIONS.md) and the report page's section (conventions_sections).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "handcentric/experiments/document.hpp"
#include "handcentric/props/checks/classifier.hpp"

namespace handcentric::experiments {

/// Pointwise cases per cell of the committed table: in distribution max(10, cases / 100) = 10,
/// injectivity max(100, cases / 5) = 100 chunk pairs (props::classifier_options).
inline constexpr int kConventionsCases = 300;

struct ConventionsOptions {
  std::string folder = "conventions";  ///< the plug-ins: every *.py not starting with '_'
  /// The interpreter that runs them, with NumPy: Debian's (another python3 may come first on
  /// PATH without it).
  std::string python = "/usr/bin/python3";
  int cases = kConventionsCases;
  std::uint64_t seed = 1;
  double timeout = 30.0;  ///< seconds per scene of a request (props::PipeRepresentation)
  /// Where the table's plug-in column links each row's file to: this prefix and NAME.py
  /// (docs/CONVENTIONS.md sits one folder below conventions/).
  std::string plugin_links = "../conventions/";
  /// Called before each plug-in's audit (name, 1-based index, count): a progress line.
  std::function<void(const std::string& name, int index, int count)> progress;
};

/// One place a row's formula was read, as its Source paragraph writes it:
/// `owner/repo@COMMIT:path:function`, COMMIT the 40 hex digits of the version read.
struct ConventionCitation {
  std::string repo, commit, path, function;
};

struct ConventionAudit {
  std::string name;                           ///< the file's stem, e.g. "umi_relative"
  std::string title;                          ///< convention_title of the docstring
  std::string description;                    ///< the whole docstring: source, formula, theory
  std::vector<ConventionCitation> citations;  ///< convention_citations of the docstring
  std::string used_by;                        ///< convention_used_by of the docstring
  props::Classification result;
  /// Where the audit disagrees with the docstring's "Expect" line, one sentence each (empty:
  /// the verdicts are what the theory says).
  std::vector<std::string> mismatches;
};

/// The plug-ins of `folder`, sorted by name (full paths). Throws InvalidArgument naming the
/// folder when it does not exist or holds none.
std::vector<std::string> convention_plugins(const std::string& folder);

/// The module docstring of a plug-in's source (the text between its first pair of triple
/// quotes). Throws InvalidArgument naming the file when there is none, or when it does not say
/// where the formula comes from ("Source") and what to expect ("Theory").
std::string convention_docstring(const std::string& path, const std::string& source);

/// The groups a docstring's "Expect" line names for `component` ("actions" or "observation"):
/// `Expect   actions: translation; observation: none` ("all": the five groups). They are the
/// groups expected to leave the component invariant pointwise in the eye-in-hand view (Theorem
/// 1's setting), and for actions also the flow target's law. Throws InvalidArgument naming the
/// file and the fix when the line is missing or names an unknown component or group.
std::vector<props::Group> expected_groups(const std::string& path, const std::string& docstring,
                                          props::Component component);

/// The cells of `result` that differ from the Expect line of `docstring`, one sentence each.
std::vector<std::string> expectation_mismatches(const std::string& path,
                                                const std::string& docstring,
                                                const props::Classification& result);

/// A docstring's title: its first paragraph up to the first ": " ("UMI, pose_rep 'abs'").
std::string convention_title(const std::string& docstring);

/// The citations of a docstring's Source paragraph, in order: every
/// `owner/repo@COMMIT:path:function`, COMMIT 40 hex digits; one longer than a line may break
/// after any of its colons and go on at the next line's indentation. Throws
/// InvalidArgument naming the file and the form when the paragraph has none (a short commit or a
/// missing function is not a citation).
std::vector<ConventionCitation> convention_citations(const std::string& path,
                                                     const std::string& docstring);

/// A docstring's Config paragraph, its lines joined: the shipped configurations that select the
/// pipeline ("no shipped config" when none does; "not on main" when the code is only on another
/// branch). Throws InvalidArgument naming the file when the paragraph is missing or empty.
std::string convention_used_by(const std::string& path, const std::string& docstring);

/// Audits every plug-in of options.folder (all groups, both views, pointwise and in
/// distribution, injectivity), each in its own process. Throws InvalidArgument for bad
/// options, and rethrows a plug-in's failure (the audit's message, naming the plug-in).
std::vector<ConventionAudit> audit_conventions(const ConventionsOptions& options);

/// docs/CONVENTIONS.md: deterministic for the same results (no paths, times or machine names;
/// witnesses rounded to 3 significant digits).
std::string conventions_markdown(const std::vector<ConventionAudit>& conventions,
                                 const ConventionsOptions& options);

/// The 1-based number of the first line where `a` and `b` differ (0 when they are equal), and
/// both lines: what an out-of-date check says.
struct FirstDifference {
  int line = 0;
  std::string first, second;
};
FirstDifference first_difference(const std::string& a, const std::string& b);

/// The report page's part: a level-2 section (the two tables, verdict cells linking to the
/// witnesses) and a level-3 section per convention (its docstring and its failing checks, each
/// row an anchor). Ids start with "conventions".
std::vector<Section> conventions_sections(const std::vector<ConventionAudit>& conventions,
                                          const ConventionsOptions& options);

}  // namespace handcentric::experiments
