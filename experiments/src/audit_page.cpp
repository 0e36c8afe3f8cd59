#include "handcentric/experiments/audit_page.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "handcentric/core/format.hpp"
#include "handcentric/experiments/witness_figure.hpp"

namespace handcentric::experiments {
namespace {

using props::Component;
using props::Mode;
using props::Verdict;
using props::View;

constexpr Component kComponents[] = {Component::actions, Component::observation,
                                     Component::flow_input, Component::flow_target,
                                     Component::policy};

std::string vector_text(const Eigen::Vector3d& v) {
  std::string text = "(";  // appends: GCC 12 warns, falsely, on "(" + std::string&&
  for (int i = 0; i < 3; ++i) {
    if (i > 0) text += ", ";
    text += format_significant(v[i], 6);
  }
  return text + ")";
}

std::string view_title(View view) {
  return view == View::eye_in_hand ? "eye-in-hand view (no world points: Theorem 1's setting)"
                                   : "third-person view (1-8 world points that move with g)";
}

std::string cell_id(const std::string& prefix, const std::string& name, const Verdict& v) {
  return slug(prefix + "-w-" + name + "-" + props::to_string(v.view) + "-" +
              props::to_string(v.component) + "-" + props::to_string(v.mode) + "-" +
              props::to_string(v.group));
}

// The witness's two outputs, coordinate by coordinate; the largest differences first when there
// are more than fit a small table.
Table coordinates_table(const std::string& id, const props::Witness& witness) {
  Table table;
  table.id = id;
  table.kind = "witness-outputs";
  table.caption = "The two outputs compared (policy: g * a(o) and a(g * o); exact law: means)";
  table.columns = {"coordinate", "f(s)", "f(g s)", "|difference|"};
  const Eigen::Index n = std::min(witness.before.size(), witness.after.size());
  std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  constexpr std::size_t kShown = 12;
  if (order.size() > kShown) {
    std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
      return std::abs(witness.after[a] - witness.before[a]) >
             std::abs(witness.after[b] - witness.before[b]);
    });
    order.resize(kShown);
    std::sort(order.begin(), order.end());
    table.caption += "; the " + std::to_string(kShown) + " largest differences of " +
                     std::to_string(n) + " coordinates";
  }
  for (Eigen::Index i : order) {
    table.rows.push_back(
        {text_cell(std::to_string(i)), text_cell(format_significant(witness.before[i], 10)),
         text_cell(format_significant(witness.after[i], 10)),
         text_cell(format_scientific(std::abs(witness.after[i] - witness.before[i]), 1))});
  }
  return table;
}

Section witness_section(const std::string& id, const std::string& name, const Verdict& verdict,
                        int cases, std::vector<PageFile>& files) {
  Section section;
  section.id = id;
  section.level = 4;
  section.title = "Witness: " + name + ", " + props::row_label(verdict.component, verdict.mode) +
                  " under " + props::to_string(verdict.group) + ", " +
                  props::to_string(verdict.view);
  if (!verdict.witness) {
    section.blocks.push_back(Paragraph{{plain(
        "The check failed without a counterexample to show (no case far from the identity held "
        "it). " +
        verdict.note)}});
    return section;
  }
  const props::Witness& w = *verdict.witness;
  Table facts;
  facts.id = id + "-facts";
  facts.kind = "witness";
  facts.caption = "The counterexample, shrunk by RapidCheck (handcentric audit --repr " + name +
                  " --cases " + std::to_string(cases) + " --seed " + std::to_string(verdict.seed) +
                  " replays it)";
  facts.columns = {"what", "value"};
  const auto fact = [&](std::string what, std::string value) {
    facts.rows.push_back({text_cell(std::move(what)), text_cell(std::move(value))});
  };
  fact("seed", std::to_string(verdict.seed));
  fact("g: rotation vector (rad)", vector_text(w.g.rotation().log()));
  fact("g: translation (m)", vector_text(w.g.translation()));
  if (!w.scene.world_T_hand_history.empty())
    fact("scene: T_0 position (m)", vector_text(w.scene.world_T_hand0().translation()));
  fact("scene: past poses H, chunk K",
       std::to_string(w.scene.history_length()) + ", " + std::to_string(w.scene.chunk_length()));
  fact("scene: world points, hand points", std::to_string(w.scene.world_points.size()) + ", " +
                                               std::to_string(w.scene.hand_points.size()));
  fact("error", format_scientific(w.error, 1));
  fact("tolerance", format_scientific(w.tolerance, 1));
  if (verdict.method == props::Method::energy_test || verdict.method == props::Method::partly_exact)
    fact("p-value (3 x the smallest)", format_significant(w.p_value, 3));
  if (!w.detail.empty()) fact("detail", w.detail);
  if (w.off_case) fact("moved off the case drawn", "yes: a symmetry breaking, not a bin edge");
  section.blocks.push_back(std::move(facts));
  if (w.before.size() > 0) section.blocks.push_back(coordinates_table(id + "-outputs", w));
  if (drawable(w.scene)) {
    const std::string path = "witness/" + id + ".svg";
    files.push_back({path, witness_svg(w.scene, w.g)});
    section.blocks.push_back(
        Figure{path,
               "the witness scene s and g s",
               {plain("The hand's path in s and in g s (axes named in the picture).")},
               0});
  }
  return section;
}

}  // namespace

std::string method_label(const Verdict& verdict) {
  switch (verdict.method) {
    case props::Method::exact_gaussian:
      return "exact";
    case props::Method::partly_exact:
      return "partly exact";
    case props::Method::energy_test:
      return "test";
    case props::Method::from_pointwise:
      return "from pointwise";
    case props::Method::compared:
      break;
  }
  return "";
}

AuditPart audit_part(const std::vector<props::Classification>& classifications,
                     const props::AuditOptions& options, const std::string& prefix) {
  AuditPart part;
  for (const props::Classification& classification : classifications) {
    Section section;
    section.id = slug(prefix + "-" + classification.name);
    section.title = classification.name;
    section.level = 3;
    std::vector<Section> witnesses;
    for (View view : options.views) {
      Table grid;
      grid.id = slug(prefix + "-" + classification.name + "-" + props::to_string(view));
      grid.kind = "verdict-grid";
      grid.caption = classification.name + ": " + view_title(view);
      grid.columns = {"component"};
      for (props::Group group : options.groups) grid.columns.push_back(props::to_string(group));
      for (Mode mode : {Mode::pointwise, Mode::distribution, Mode::closed_loop}) {
        for (Component component : kComponents) {
          std::vector<TableCell> row = {text_cell(props::row_label(component, mode))};
          bool any = false;
          for (props::Group group : options.groups) {
            const Verdict* verdict =
                props::find_verdict(classification, component, mode, group, view);
            if (verdict == nullptr) {
              row.push_back(text_cell("not checked"));
              continue;
            }
            any = true;
            std::string link;
            if (!verdict->invariant) {
              link = cell_id(prefix, classification.name, *verdict);
              witnesses.push_back(
                  witness_section(link, classification.name, *verdict, options.cases, part.files));
              link = "#" + link;
            }
            TableCell cell =
                verdict_cell(verdict->invariant, format_scientific(verdict->max_error, 1) + " m/1",
                             method_label(*verdict), link);
            cell.tooltip = std::to_string(verdict->cases) + " cases, seed " +
                           std::to_string(verdict->seed) +
                           (verdict->note.empty() ? "" : "; " + verdict->note);
            row.push_back(std::move(cell));
          }
          if (any) grid.rows.push_back(std::move(row));
        }
      }
      section.blocks.push_back(std::move(grid));
    }
    std::vector<Text> notes;
    // The laws taken from their pointwise cells (policy_audit.hpp): one note for all of them.
    int derived = 0;
    for (const Verdict& verdict : classification.verdicts) {
      if (verdict.method == props::Method::from_pointwise) {
        ++derived;
        continue;
      }
      if (!verdict.note.empty()) {
        notes.push_back({plain(props::row_label(verdict.component, verdict.mode) + " under " +
                               props::to_string(verdict.group) + ", " +
                               props::to_string(verdict.view) + ": " + verdict.note)});
      }
    }
    if (derived > 0) {
      notes.push_back({plain(props::derived_laws_note(derived, "marked 'from pointwise'"))});
    }
    if (const auto& injectivity = classification.injectivity) {
      const std::string verdict = !injectivity->injective.has_value() ? "not decided"
                                  : *injectivity->injective           ? "yes"
                                                                      : "NO";
      notes.push_back({bold("injective: " + verdict), plain(" (" + injectivity->how + ")")});
    }
    if (!notes.empty()) section.blocks.push_back(List{std::move(notes)});
    part.grids.push_back(std::move(section));
    if (!witnesses.empty()) {
      Section heading;
      heading.id = slug(prefix + "-witnesses-" + classification.name);
      heading.title = "Witnesses: " + classification.name;
      heading.level = 3;
      heading.blocks.push_back(Paragraph{
          {plain(std::to_string(witnesses.size()) + " failing cell(s) of "),
           plain(classification.name, "#" + part.grids.back().id),
           plain("'s grids, each a scene s, a global transform g and the two outputs that "
                 "differ.")}});
      part.witnesses.push_back(std::move(heading));
      for (Section& witness : witnesses) part.witnesses.push_back(std::move(witness));
    }
  }
  return part;
}

}  // namespace handcentric::experiments
