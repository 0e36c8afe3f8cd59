#pragma once
// The page of one `handcentric audit` (`--page DIR`): what a reviewer opens and cites. Its
// header (the lines the command prints above its tables), one verdict grid per classification
// and view (a policy plug-in's outputs each their own, with their closed-loop rows), and the
// witness of every NO cell with its picture (audit_page.hpp), as DIR/index.html and
// DIR/index.md with the pictures beside them.
#include <string>
#include <vector>

#include "handcentric/props/audit.hpp"

namespace handcentric::experiments {

/// Writes the page into `dir` (created when missing). `header` is shown verbatim above the
/// grids. Everything is built and checked (document.hpp's check) before the first file is
/// written, each file atomically. Throws InvalidArgument for an empty `dir`, FileError when a
/// file cannot be written.
void write_audit_page(const std::string& dir, const std::vector<props::Classification>& results,
                      const props::AuditOptions& options, const std::string& header);

}  // namespace handcentric::experiments
