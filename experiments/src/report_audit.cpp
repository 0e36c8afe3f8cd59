#include "handcentric/experiments/report_audit.hpp"

#include "handcentric/props/checks/classifier.hpp"

namespace handcentric::experiments {

props::AuditOptions report_audit_options(long long cases, std::uint64_t seed) {
  props::AuditOptions audit;
  audit.cases = props::checked_cases(cases);  // 1 to props::kMaxCases
  audit.seed = seed;
  return audit;
}

ReportAudit run_report_audit(long long cases, std::uint64_t seed) {
  ReportAudit out;
  out.options = report_audit_options(cases, seed);
  out.classifier = props::classifier_options(out.options);
  out.results = props::audit_builtins({}, out.options);
  for (const props::Classification& classification : out.results) {
    for (std::string& line : props::mismatches_with_paper(classification))
      out.mismatches.push_back(std::move(line));
  }
  return out;
}

}  // namespace handcentric::experiments
