#!/usr/bin/env bash
# scripts/check_report_html.sh on a report page (handcentric report --out PAGE) and on copies of
# it with one planted fault each: a missing table, a broken image, a broken link, a verdict grid
# in a <pre> block, a NO cell without its link. The page must pass and every copy fail, naming
# its fault.
#   bash check_report_html_faults.sh CHECK_SCRIPT PAGE WORKDIR
set -euo pipefail
check="$1" page="$2" work="$3"
rm -rf "$work"
mkdir -p "$work"
# Each check runs in the background: Chromium spends most of a check's ~10 s waiting, not
# computing (~3 s of CPU), so the seven run side by side; results are read after `wait`.
bash "$check" "$page" >"$work/good.out" 2>&1 &
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
  printf '%s\n' "$expected" >"$work/$name.expected"
  { if bash "$check" "$work/$name" --no-screenshot >"$work/$name.out" 2>&1; then
      echo passed >"$work/$name.status"
    else
      echo failed >"$work/$name.status"
    fi; } &
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
wait
grep -q 'check_report_html: ok' "$work/good.out" ||
  { echo "the good page fails the check: $(cat "$work/good.out")"; exit 1; }
echo "good page passes"
for expected_file in "$work"/*.expected; do
  name="$(basename "$expected_file" .expected)"
  status="$(cat "$work/$name.status" 2>/dev/null || echo "no status")"
  [ "$status" != passed ] || { echo "planted $name: the check PASSED a faulty page"; exit 1; }
  [ "$status" = failed ] || { echo "planted $name: the check left no status"; exit 1; }
  grep -qF "$(cat "$expected_file")" "$work/$name.out" ||
    { echo "planted $name: wrong message: $(cat "$work/$name.out")"; exit 1; }
  echo "planted $name: caught"
done
echo "all planted faults caught"
