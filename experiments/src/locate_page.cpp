#include "handcentric/experiments/locate_page.hpp"

#include <memory>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/experiments/layer_fault.hpp"
#include "handcentric/experiments/model_audit.hpp"
#include "handcentric/experiments/model_locate.hpp"

namespace handcentric::experiments {
namespace {

// One model's cell of a layer: its verdict, its error, and where it broke first.
TableCell located_layer_cell(const LocatedLayer& layer, bool first) {
  std::string detail = "error " + format_significant(layer.error, 3);
  if (layer.breaks) {
    detail += first ? "; FIRST BREAK, case " + std::to_string(layer.first_case)
                    : "; after the first break";
  }
  TableCell cell =
      verdict_cell(!layer.breaks, layer.verdict, detail, layer.breaks ? "#locate-witness" : "");
  if (first) cell.text = {bold(layer.verdict + " (first break)")};
  return cell;
}

std::string located_layer_label(const LocatedLayer& layer) {
  return layer.name + "[" + std::to_string(layer.call) + "]";
}

std::string located_outcome(const ModelLocation& r) {
  const LocatedLayer* first = r.first_break();
  return first ? "first break at " + located_layer_label(*first) +
                     (r.witness ? " in case " + std::to_string(r.witness->case_number) : "")
               : "no layer breaks its kind";
}

// The witness of the first break, or that none broke; and the chunk's own verdict.
std::string located_witness(const ModelLocation& r) {
  const auto chunk = std::string(" The policy's chunk: ") +
                     (r.chunk_equivariant ? "equivariant" : "not equivariant") + " (error " +
                     format_significant(r.chunk_error, 3) + ").";
  if (!r.witness) return "no layer breaks its kind." + chunk;
  const LocateWitness& w = *r.witness;
  const Eigen::Vector3d rotation = w.g.rotation().log(), p = w.g.translation();
  const auto vec = [](const Eigen::Vector3d& v) {
    return "(" + format_significant(v.x(), 3) + ", " + format_significant(v.y(), 3) + ", " +
           format_significant(v.z(), 3) + ")";
  };
  return w.name + "[" + std::to_string(w.call) + "] breaks first, in case " +
         std::to_string(w.case_number) + " (g: rotation vector " + vec(rotation) +
         ", translation " + vec(p) + "): its error " + format_significant(w.case_error, 3) +
         " is above the tolerance " + format_significant(w.tolerance, 3) +
         " at the output's size c = " + format_significant(w.scale, 3) +
         "; every layer before it holds." + chunk;
}

}  // namespace

std::vector<Section> locate_sections(const std::string& model, const std::string& shown,
                                     props::Group group, int cases, std::uint64_t seed) {
  const std::shared_ptr<policy::LearnedPolicy> clean = load_audited_model(model);
  const auto faulty = std::make_shared<WorldFrameBias>(clean, kReportFaultLayer);
  props::AuditOptions audit;
  audit.groups = {group};
  audit.cases = cases;
  audit.seed = seed;
  const ModelLocation a = locate_on_model_cases(clean, clean->config(), audit, group);
  const ModelLocation b = locate_on_model_cases(faulty, clean->config(), audit, group);
  if (a.layers.size() != b.layers.size())
    throw InvalidArgument("locate_section: the planted fault changed the model's layers");

  Section out;
  out.id = "locate";
  out.title = "Where the symmetry breaks: a planted fault located";
  const std::string group_name = props::to_string(group);
  out.blocks.push_back(Paragraph{
      {plain("Each layer's output of " + shown + " (" + clean->name() +
             ") on the audit's own pointwise cases under " + group_name + " (" +
             std::to_string(cases) + " cases, seed " + std::to_string(seed) +
             "), beside the same model with a world-frame bias (0.1 times the x of the hand "
             "pose T_0) added to every unit of " +
             kReportFaultLayer +
             ": the observation vector, the MLP's layers at each Euler step (the call index), "
             "the raw action vector must be invariant, the decoded chunk equivariant; a layer "
             "breaks when its error exceeds REL (1 + c) and its own rounding. As "),
       code("handcentric audit --model M --locate --group " + group_name),
       plain(" prints it; how a layer is decided: docs/AUDIT.md, \"Localizing a break\". "
             "Hand-centric: " +
             located_outcome(a) + ". Planted fault: " + located_outcome(b) + ".")}});
  Table table;
  table.id = "locate-layers";
  table.kind = "results";
  table.caption = "Per layer, in execution order: verdict and largest error / (1 + c)";
  table.columns = {"layer", "kind", "hand-centric model",
                   std::string("bias in ") + kReportFaultLayer};
  const LocatedLayer* first_a = a.first_break();
  const LocatedLayer* first_b = b.first_break();
  for (std::size_t i = 0; i < a.layers.size(); ++i) {
    const LocatedLayer& x = a.layers[i];
    const LocatedLayer& y = b.layers[i];
    TableCell label = text_cell(located_layer_label(x));
    if (&y == first_b || &x == first_a) label.text = {bold("▶ " + located_layer_label(x))};
    table.rows.push_back({std::move(label), text_cell(to_string(x.kind)),
                          located_layer_cell(x, &x == first_a),
                          located_layer_cell(y, &y == first_b)});
  }
  out.blocks.push_back(std::move(table));
  // The witnesses, where the NO cells link.
  Section witnesses;
  witnesses.id = "locate-witness";
  witnesses.title = "The first breaks' witnesses";
  witnesses.level = 3;
  for (const auto& [who, r] :
       {std::pair<std::string, const ModelLocation*>{"Hand-centric", &a}, {"Planted fault", &b}}) {
    witnesses.blocks.push_back(Paragraph{{bold(who + ": "), plain(located_witness(*r))}});
  }
  return {std::move(out), std::move(witnesses)};
}

}  // namespace handcentric::experiments
