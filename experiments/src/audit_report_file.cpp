#include "handcentric/experiments/audit_report_file.hpp"

#include <filesystem>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/audit_page.hpp"
#include "handcentric/experiments/document_html.hpp"
#include "handcentric/experiments/document_markdown.hpp"

namespace handcentric::experiments {

void write_audit_page(const std::string& dir, const std::vector<props::Classification>& results,
                      const props::AuditOptions& options, const std::string& header) {
  if (dir.empty()) throw InvalidArgument("--page needs a folder, e.g. --page audit_page");
  Document doc;
  doc.title = "handcentric audit";  // what was audited: the header and the grids' titles
  doc.intro.push_back(Preformatted{header});
  doc.intro.push_back(Paragraph{
      {plain("One grid per audited map and view; a NO cell links to its witness below (the "
             "scene, g, both outputs and a picture). What the verdicts mean: docs/AUDIT.md.")}});
  AuditPart part = audit_part(results, options);
  doc.sections = std::move(part.grids);
  if (!part.witnesses.empty()) {
    Section appendix;
    appendix.id = "witnesses";
    appendix.title = "The witnesses of the NO cells";
    doc.sections.push_back(std::move(appendix));
    for (Section& s : part.witnesses) doc.sections.push_back(std::move(s));
  }
  // Everything is built and checked before the first file is written.
  const std::string html = to_html(doc);
  const std::string markdown = to_markdown(doc);
  const std::filesystem::path folder(dir);
  std::error_code error;  // audit_part puts every picture under witness/
  std::filesystem::create_directories(folder / "witness", error);
  if (error) {
    throw FileError("--page " + dir + ": cannot create the folder (" + error.message() +
                    "); give a folder you can write, e.g. --page audit_page");
  }
  for (const PageFile& file : part.files)
    write_file_atomically((folder / file.path).string(), file.bytes);
  write_file_atomically((folder / "index.md").string(), markdown);
  write_file_atomically((folder / "index.html").string(), html);
}

}  // namespace handcentric::experiments
