#pragma once
// The report page's section "Where the symmetry breaks" (report_page.hpp): a hand-centric model
// and the same model with a world-frame bias planted in its second layer (layer_fault.hpp),
// located layer by layer (model_locate.hpp) on the same cases, side by side.
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/experiments/document.hpp"
#include "handcentric/props/group.hpp"

namespace handcentric::experiments {

/// The cases the report locates on (each case asks the model 6 times).
inline constexpr int kReportLocateCases = 50;

/// The layer the report plants its world-frame bias in.
inline constexpr const char* kReportFaultLayer = "mlp.layer2";

/// The section (id "locate") and its subsection of witnesses ("locate-witness"): the model file
/// `model` (shown as `shown`) and the same model with a world-frame bias in kReportFaultLayer,
/// located under `group` on `cases` pointwise cases from `seed`; one row per layer and call, each
/// model's verdict and error in a column, the first break marked. Throws what loading and locating
/// throw (InvalidModelFile, InvalidArgument).
std::vector<Section> locate_sections(const std::string& model, const std::string& shown,
                                     props::Group group, int cases, std::uint64_t seed);

}  // namespace handcentric::experiments
