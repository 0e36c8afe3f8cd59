#!/usr/bin/env bash
# scripts/check_report_html.sh on a report page (handcentric report --out PAGE) and on copies of
# it with one planted fault each: a missing table, a broken image, a broken link, a verdict grid
# in a <pre> block, a NO cell without its link. The page must pass and every copy fail, naming
# its fault.
#   bash check_report_html_faults.sh CHECK_SCRIPT PAGE WORKDIR
set -euo pipefail
check="$1" page="$2" work="$3"
bash "$check" "$page" >/dev/null || { echo "the good page fails the check"; exit 1; }
echo "good page passes"
rm -rf "$work"
mkdir -p "$work"
plant() {  # plant NAME EXPECTED-MESSAGE PYTHON-REPLACEMENT
  local name="$1" expected="$2" edit="$3"
  cp -r "$page" "$work/$name"
  /usr/bin/python3 - "$work/$name/index.html" "$edit" <<'PY'
import re, sys
path, edit = sys.argv[1], sys.argv[2]
html = open(path, encoding="utf-8").read()
old = html
exec(edit)
if html == old:
    sys.exit("planting changed nothing: " + edit)
open(path, "w", encoding="utf-8").write(html)
PY
  local out
  if out="$(bash "$check" "$work/$name" --no-screenshot 2>&1)"; then
    echo "planted $name: the check PASSED a faulty page"; exit 1
  fi
  grep -q "$expected" <<<"$out" || { echo "planted $name: wrong message: $out"; exit 1; }
  echo "planted $name: caught"
}
plant missing_table "table missing or empty: #claims" \
  'html = re.sub(r"<table id=\"claims\".*?</table>", "", html, flags=re.S)'
plant broken_image "image did not load: fig3-missing.png" \
  'html = html.replace("src=\"fig3.png\"", "src=\"fig3-missing.png\"")'
plant broken_link "link to a missing anchor of claims.html" \
  'html = re.sub(r"claims.html#L[0-9]+", "claims.html#L99999", html, count=1)'
plant missing_file "link to a missing file: nowhere.md" \
  'html = html.replace("href=\"index.md\"", "href=\"nowhere.md\"")'
plant grid_in_pre "a <pre> holds a verdict grid" \
  'html = html.replace("</body>", "<pre>actions | NO   1.0e+01   | yes  5.7e-14</pre></body>")'
plant no_cell_unlinked "a NO cell links to no witness" \
  'html = re.sub(r"(<td class=\"no\"[^>]*>)<a href=\"[^\"]*\">(.*?)</a></td>", r"\1\2</td>",
                html, count=1)'
echo "all planted faults caught"
