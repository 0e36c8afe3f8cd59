#!/usr/bin/env bash
# Opens a report page (handcentric report --out DIR) in headless Chromium, checks that every
# image on it loaded (a broken path shows as an image of width 0), and saves a screenshot of the
# page's top as DIR/screenshot.png to look at. Needs Debian's chromium (apt-get install chromium).
#   bash scripts/check_report_html.sh DIR
set -euo pipefail
arg="${1:?usage: check_report_html.sh DIR (a handcentric report --out DIR)}"
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
# A page that loads the report in a frame and writes, once everything loaded, how many images
# there are and which did not load.
cat > "$checker" <<'HTML'
<!DOCTYPE html><html><body><iframe id="f" src="index.html" width="1400" height="900"></iframe>
<pre id="result">pending</pre>
<script>
document.getElementById('f').onload = function () {
  var images = Array.from(this.contentDocument.images);
  var broken = images.filter(function (i) { return !i.complete || i.naturalWidth === 0; });
  document.getElementById('result').textContent =
      'RESULT images=' + images.length + ' broken=' + broken.length +
      (broken.length
           ? ' ' + broken.map(function (i) { return i.getAttribute('src'); }).join(',')
           : '');
};
</script></body></html>
HTML
result="$(timeout 120 chromium "${flags[@]}" --virtual-time-budget=10000 \
            --dump-dom "file://$checker" 2>/dev/null |
          grep -oE 'RESULT images=[0-9]+ broken=[0-9]+[^<]*' || true)"
timeout 120 chromium "${flags[@]}" --window-size=1400,2400 --screenshot="$dir/screenshot.png" \
  "file://$dir/index.html" >/dev/null 2>&1
echo "check_report_html: ${result:-no result (the page did not finish loading)};" \
     "screenshot: $dir/screenshot.png"
case "$result" in
  *"broken=0"*) [ "${result#*images=0 }" = "$result" ] ||
                  { echo "check_report_html: the page has no image" >&2; exit 1; } ;;
  *) exit 1 ;;
esac
