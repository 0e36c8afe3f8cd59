#!/usr/bin/env bash
# Opens a report page (handcentric report --out DIR) in headless Chromium as a reader would and
# fails when the page is not what a reviewer can use:
#   - a table is missing: the verdict grids (class verdict-grid, at least one per audited
#     representation and view), the certificates (#claims), the sim's bar (#sim-bar), Table 1
#     (#table1-rows), Table 2 (#table2-rows) and Fig. 5's grid (#fig5-rows);
#   - an image did not load (a broken path shows as an image of width 0);
#   - a link is broken: "#id" to no element of the page, a file beside the page that does not
#     exist, or "file.html#id" to no element of that file; a NO cell that links nowhere;
#   - a <pre> block holds a verdict grid (yes/NO beside an error, the terminal's layout) or the
#     page has no table of contents.
# It saves screenshots of the page's top and of its first witness as DIR/screenshot.png and
# DIR/screenshot-witness.png, to look at. Needs Debian's chromium (apt-get install chromium).
#   bash scripts/check_report_html.sh DIR [--no-screenshot]
# (--no-screenshot: the checks only, two Chromium starts fewer; the planted-fault test uses it.)
set -euo pipefail
arg="${1:?usage: check_report_html.sh DIR [--no-screenshot] (a handcentric report --out DIR)}"
screenshots=1
case "${2:-}" in
  "") ;;
  --no-screenshot) screenshots=0 ;;
  *) echo "check_report_html: unknown option '$2': use --no-screenshot or nothing" >&2; exit 1 ;;
esac
[ -d "$arg" ] || {
  echo "check_report_html: $arg is not a folder: run handcentric report --out $arg first" >&2
  exit 1
}
dir="$(cd "$arg" && pwd)"
[ -f "$dir/index.html" ] || {
  echo "check_report_html: $dir/index.html does not exist:" \
       "run handcentric report --out $dir first" >&2
  exit 1
}
command -v chromium >/dev/null ||
  { echo "check_report_html: chromium is not installed: apt-get install chromium" >&2; exit 1; }
profile="$(mktemp -d)"
checker="$(mktemp --suffix=.html -p "$dir")"
trap 'rm -rf "$profile" "$checker"' EXIT
# The flags keep Chromium off the network (this machine has none) and out of the user's profile.
flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run
       --disable-background-networking --disable-component-update --disable-sync
       --user-data-dir="$profile" --allow-file-access-from-files)
# A page that loads the report in a frame and, once everything loaded, writes one line per
# finding: FAULT lines for what is wrong on the page itself, LINK lines for links to other files
# (checked below, outside the browser), and a RESULT line.
cat > "$checker" <<'HTML'
<!DOCTYPE html><html><body><iframe id="f" src="index.html" width="1400" height="900"></iframe>
<pre id="result">pending</pre>
<script>
document.getElementById('f').onload = function () {
  var d = this.contentDocument, out = [];
  var fault = function (what) { out.push('FAULT ' + what); };
  var images = Array.from(d.images);
  images.forEach(function (i) {
    if (!i.complete || i.naturalWidth === 0) fault('image did not load: ' + i.getAttribute('src'));
  });
  ['claims', 'sim-bar', 'table1-rows', 'table2-rows', 'fig5-rows'].forEach(function (id) {
    var t = d.getElementById(id);
    if (!t || t.tagName !== 'TABLE' || t.tBodies.length === 0 || t.tBodies[0].rows.length === 0)
      fault('table missing or empty: #' + id);
  });
  var grids = d.querySelectorAll('table.verdict-grid');
  if (grids.length === 0) fault('table missing: no verdict grid (table.verdict-grid)');
  grids.forEach(function (g) {
    if (g.querySelectorAll('td.yes, td.no').length === 0)
      fault('verdict grid #' + g.id + ' has no yes/NO cell');
  });
  d.querySelectorAll('td.no').forEach(function (c) {
    var a = c.querySelector('a[href]');
    if (!a) fault('a NO cell links to no witness: ' + c.textContent.trim());
  });
  if (!d.querySelector('nav a[href^="#"]')) fault('no table of contents');
  var grid = /\b(yes|NO)\b\s+[0-9.]+e[+-]?[0-9]+/;
  d.querySelectorAll('pre').forEach(function (p) {
    if (grid.test(p.textContent)) fault('a <pre> holds a verdict grid: ' +
                                       p.textContent.trim().slice(0, 60));
  });
  var links = 0;
  d.querySelectorAll('a[href]').forEach(function (a) {
    var href = a.getAttribute('href');
    links++;
    if (href.charAt(0) === '#') {
      if (!d.getElementById(decodeURIComponent(href.slice(1))))
        fault('link to a missing anchor: ' + href);
    } else if (/^[a-z]+:/i.test(href)) {
      fault('link off the page (the page must work offline): ' + href);
    } else {
      out.push('LINK ' + href);
    }
  });
  out.push('RESULT images=' + images.length + ' tables=' + d.querySelectorAll('table').length +
           ' grids=' + grids.length + ' links=' + links);
  // One finding a line, none on the lines of the <pre> tags themselves.
  document.getElementById('result').textContent = '\n' + out.join('\n') + '\n';
};
</script></body></html>
HTML
dom="$(timeout 120 chromium "${flags[@]}" --virtual-time-budget=15000 \
         --dump-dom "file://$checker" 2>/dev/null || true)"
# --dump-dom writes the findings as HTML text: their entities decoded, '&' last.
report="$(printf '%s\n' "$dom" | grep -E '^(FAULT|LINK|RESULT) ' |
          sed 's/&lt;/</g; s/&gt;/>/g; s/&quot;/"/g; s/&amp;/\&/g' || true)"
faults="$(printf '%s\n' "$report" | grep '^FAULT ' || true)"
result="$(printf '%s\n' "$report" | grep '^RESULT ' || true)"
# Links to files beside the page: the file must exist, and a fragment into an HTML file must
# name an id there.
while read -r _ link; do
  [ -n "$link" ] || continue
  file="${link%%#*}"
  fragment=""
  [ "$file" = "$link" ] || fragment="${link#*#}"
  if [ ! -e "$dir/$file" ]; then
    faults+=$'\n'"FAULT link to a missing file: $link"
  elif [ -n "$fragment" ] && [ "${file##*.}" = html ] &&
       ! grep -q "id=\"$fragment\"" "$dir/$file"; then
    faults+=$'\n'"FAULT link to a missing anchor of $file: $link"
  fi
done < <(printf '%s\n' "$report" | grep '^LINK ' | sort -u)
# The top of the page, and the first witness (when there is one), to look at.
if [ "$screenshots" = 1 ]; then
  timeout 120 chromium "${flags[@]}" --hide-scrollbars --virtual-time-budget=5000 \
    --window-size=1400,2400 --screenshot="$dir/screenshot.png" \
    "file://$dir/index.html" >/dev/null 2>&1 || true
fi
witness="$(grep -o 'href="#audit-w-[^"]*"' "$dir/index.html" | head -n 1 | cut -d'"' -f2 || true)"
if [ "$screenshots" = 1 ] && [ -n "$witness" ]; then
  # Chromium's --screenshot ignores a URL's fragment; a frame scrolled to it does not.
  printf '<!DOCTYPE html><body style="margin:0"><iframe src="index.html%s" width="1400" %s' \
    "$witness" 'height="1400" style="border:0"></iframe></body>' > "$checker"
  timeout 120 chromium "${flags[@]}" --hide-scrollbars --virtual-time-budget=5000 \
    --window-size=1400,1400 --screenshot="$dir/screenshot-witness.png" "file://$checker" \
    >/dev/null 2>&1 || true
fi
faults="$(printf '%s\n' "$faults" | sed '/^$/d')"
if [ -z "$result" ]; then
  echo "check_report_html: no result: the page did not finish loading in Chromium" >&2
  exit 1
fi
echo "check_report_html: ${result#RESULT }$([ "$screenshots" = 0 ] ||
                                             echo "; screenshot: $dir/screenshot.png")"
if [ -n "$faults" ]; then
  printf '%s\n' "$faults" | sed 's/^FAULT /check_report_html: /' >&2
  echo "check_report_html: FAILED ($(printf '%s\n' "$faults" | wc -l) fault(s))" >&2
  exit 1
fi
echo "check_report_html: ok"
