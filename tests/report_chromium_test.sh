#!/usr/bin/env bash
# The HTML report of `mfr compare` in real headless Chromium: generates a small report, loads it,
# and checks that
#   - the browser logs no console message (the page's one inline script logs nothing, so any is
#     an error), no uncaught exception and no failed resource load;
#   - the DOM has the recommendation (a winner named per budget, the Pareto fronts' ringed
#     points), the ranking and results tables (sortable), the plots, the wipers, the worst-region
#     crops and every <img>, each naming a file that exists;
#   - every image actually decodes in the browser, clicking a header sorts its table (ascending,
#     then descending, the ground truth pinned on top) and moving a wiper's slider or choosing
#     its method changes what it shows (a test-only wrapper page drives the report in an iframe);
#   - the temporal report (--orbit) loads the same way: no console message, its three SVG plots,
#     its sortable table and its frames as images of files that exist, and results.csv;
#   - a screenshot is written and is not blank.
# Usage: report_chromium_test.sh path/to/mfr. Exit 77 (skipped) when Chromium is not installed.
set -euo pipefail

mfr=${1:?usage: report_chromium_test.sh path/to/mfr}
chromium=""
for c in chromium chromium-browser google-chrome; do
  if command -v "$c" >/dev/null 2>&1; then
    chromium=$(command -v "$c")
    break
  fi
done
if [ -z "$chromium" ]; then
  echo "report_chromium_test: SKIPPED: chromium is not installed (apt-get install chromium)"
  exit 77
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/mfr_report_test.XXXXXX")
trap 'rm -rf "$work"' EXIT
out="$work/report"
fail() {
  echo "report_chromium_test: FAIL: $*" >&2
  exit 1
}

# a small report: two budgets (so the plots are drawn), a method that fails at the first budget
"$mfr" compare 'procedural:hairball?strands=200' --width 96 --height 96 --threads 2 \
  --budget 200KB,400KB --methods fkb,kplus-dynamic,vkb,vkb-fill,abuffer --out "$out" --quiet ||
  fail "mfr compare failed"
[ -f "$out/report.html" ] || fail "no report.html"

browser() {  # browser OUTFILE LOGFILE ARGS... : one headless Chromium run with a fresh profile
  local stdout=$1 log=$2
  shift 2
  local profile
  profile=$(mktemp -d "$work/profile.XXXXXX")
  timeout 120 "$chromium" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --disable-default-apps --mute-audio --hide-scrollbars --user-data-dir="$profile" \
    --enable-logging=stderr --v=0 "$@" >"$stdout" 2>"$log" || fail "chromium exited with $? ($*)"
}

url="file://$out/report.html"

# 1. DOM and log
browser "$work/dom.html" "$work/dom.log" --dump-dom "$url"
if grep -E 'CONSOLE|Uncaught|Failed to load resource|net::ERR_|Not allowed to load' "$work/dom.log"; then
  fail "console errors or failed loads in the log above"
fi
dom="$work/dom.html"
grep -q '<table class="results" data-sortable="">' "$dom" || fail "no sortable results table"
tables=$(grep -o '<table class="results" data-sortable="">' "$dom" | wc -l)
[ "$tables" -eq 2 ] || fail "expected 2 results tables (one per budget), found $tables"
rankings=$(grep -o '<table class="results ranking" data-sortable="">' "$dom" | wc -l)
[ "$rankings" -eq 2 ] || fail "expected 2 ranking tables (one per budget), found $rankings"
grep -q 'id="recommendation"' "$dom" || fail "no recommendation section"
winners=$(grep -o '<strong class="winner">' "$dom" | wc -l)
[ "$winners" -eq 2 ] || fail "expected a winner named per budget, found $winners"
grep -q 'aria-label="Mean FLIP vs time"' "$dom" || fail "no error-vs-time front"
fronts=$(grep -o '<g class="point front"' "$dom" | wc -l)
[ "$fronts" -ge 2 ] || fail "expected ringed Pareto-front points, found $fronts"
wipers=$(grep -o '<div class="wiper"' "$dom" | wc -l)
[ "$wipers" -eq 2 ] || fail "expected a wiper per budget, found $wipers"
grep -q '<input type="range"' "$dom" || fail "no wiper slider"
grep -q '<figure class="cropset"' "$dom" || fail "no worst-region crops"
svgs=$(grep -o '<svg' "$dom" | wc -l)
[ "$svgs" -ge 2 ] || fail "expected the error-vs-budget plots, found $svgs <svg>"
grep -q 'Mean FLIP vs budget' "$dom" || fail "no FLIP plot"
grep -q 'abuffer at 200KB: needs at least' "$dom" || fail "the failed run is not on the page"
grep -q '<script src' "$dom" && fail "the report loads a script"
scripts=$(grep -o '<script' "$dom" | wc -l)
[ "$scripts" -eq 1 ] || fail "expected one inline script, found $scripts"
images=$(grep -o '<img [^>]*src="[^"]*"' "$dom" | sed 's/.*src="\([^"]*\)"/\1/')
count=$(printf '%s\n' "$images" | grep -c . || true)
[ "$count" -ge 30 ] || fail "expected at least 30 <img> elements, found $count"
while IFS= read -r src; do
  [ -f "$out/$src" ] || fail "<img src=\"$src\"> but $out/$src does not exist"
done <<<"$images"
pngs=$(cd "$out" && ls ./*.png | wc -l)
distinct=$(printf '%s\n' "$images" | sort -u | wc -l)
[ "$distinct" -eq "$pngs" ] || fail "$pngs PNG files written but $distinct shown on the page"

# 2. every image decodes; sorting and the wiper work (driven from a wrapper page)
cat >"$out/decode_check.html" <<'EOF'
<!DOCTYPE html><html><head><meta charset="utf-8"><link rel="icon" href="data:,"></head><body>
<pre id="result">MFR_IMAGES pending</pre>
<pre id="interact">MFR_INTERACT pending</pre>
<iframe id="report" src="report.html" style="width:1400px;height:2000px"></iframe>
<script>
function column(table, i) {  // the sort keys of the unpinned, successful rows, in order
  return Array.prototype.filter.call(table.tBodies[0].rows, function (r) {
    return !r.classList.contains('pinned') && !r.classList.contains('failed');
  }).map(function (r) { return parseFloat(r.cells[i].getAttribute('data-v')); });
}
function sorted(v, dir) {
  for (var k = 1; k < v.length; ++k) if ((v[k] - v[k - 1]) * dir < 0) return false;
  return v.length > 1;
}
function interact(doc) {
  var table = doc.querySelector('table.results[data-sortable]:not(.ranking)');
  var heads = Array.prototype.slice.call(table.tHead.rows[0].cells), i = -1;
  heads.forEach(function (h, k) { if (h.textContent.indexOf('FLIP') === 0) i = k; });
  if (i < 0) return 'no FLIP column';
  var before = column(table, i);
  heads[i].click();
  var up = column(table, i);
  if (!sorted(up, 1)) return 'not ascending after one click: ' + up;
  if (!table.tBodies[0].rows[0].classList.contains('pinned')) return 'ground truth not on top';
  heads[i].click();
  var down = column(table, i);
  if (!sorted(down, -1)) return 'not descending after two clicks: ' + down;
  if (down[0] === up[0]) return 'the order did not change: ' + before + ' / ' + down;
  if (heads[i].getAttribute('aria-sort') !== 'descending') return 'aria-sort not set';
  var w = doc.querySelector('.wiper'), range = w.querySelector('input[type=range]');
  var over = w.querySelector('img.over');
  range.value = 20;
  range.dispatchEvent(new Event('input'));
  if (over.style.clipPath.indexOf('80%') < 0) return 'wiper did not move: ' + over.style.clipPath;
  var select = w.querySelector('select');
  if (select.options.length < 2) return 'the wiper offers one method only';
  select.selectedIndex = 1;
  select.dispatchEvent(new Event('change'));
  if (over.getAttribute('src') !== select.options[1].value) return 'wiper kept its method';
  return 'ok';
}
document.getElementById('report').addEventListener('load', function () {
  var out = document.getElementById('result');
  try {
    var images = Array.prototype.slice.call(this.contentDocument.images), broken = [];
    images.forEach(function (i) {
      if (!(i.complete && i.naturalWidth > 0)) broken.push(i.getAttribute('src'));
    });
    out.textContent = 'MFR_IMAGES total=' + images.length + ' broken=' + broken.length + ' ' +
                      broken.join(' ');
    document.getElementById('interact').textContent =
        'MFR_INTERACT ' + interact(this.contentDocument);
  } catch (e) {
    out.textContent = 'MFR_IMAGES error ' + e;
  }
});
</script></body></html>
EOF
browser "$work/decode.html" "$work/decode.log" --allow-file-access-from-files --dump-dom \
  "file://$out/decode_check.html"
if grep -E 'CONSOLE|Uncaught' "$work/decode.log"; then
  fail "console messages while driving the report"
fi
result=$(grep -o 'MFR_IMAGES [^<]*' "$work/decode.html" | head -n 1)
echo "report_chromium_test: $result"
case "$result" in
  "MFR_IMAGES total=$count broken=0 "*) ;;
  *) fail "images did not all decode: $result (expected total=$count broken=0)" ;;
esac
interaction=$(grep -o 'MFR_INTERACT [^<]*' "$work/decode.html" | head -n 1)
echo "report_chromium_test: $interaction"
[ "$interaction" = "MFR_INTERACT ok" ] || fail "sorting or the wiper failed: $interaction"
rm "$out/decode_check.html"

# 2b. the temporal report: the same style, its plots inline, its frames as images
orbit="$work/orbit"
"$mfr" compare 'procedural:hairball?strands=100' --width 48 --height 48 --threads 2 --orbit 3 \
  --orbit-step 5 --budget 100KB --methods fkb,kplus-dynamic --composite kbuffer --out "$orbit" --quiet ||
  fail "mfr compare --orbit failed"
[ -f "$orbit/results.csv" ] || fail "no results.csv next to the temporal results.json"
browser "$work/orbit_dom.html" "$work/orbit_dom.log" --dump-dom "file://$orbit/report.html"
if grep -E 'CONSOLE|Uncaught|Failed to load resource|net::ERR_|Not allowed to load' \
  "$work/orbit_dom.log"; then
  fail "console errors or failed loads in the temporal report"
fi
orbit_svgs=$(grep -o '<svg' "$work/orbit_dom.html" | wc -l)
[ "$orbit_svgs" -eq 3 ] || fail "expected 3 SVG plots in the temporal report, found $orbit_svgs"
grep -q '<table class="results" data-sortable="">' "$work/orbit_dom.html" ||
  fail "no sortable table in the temporal report"
orbit_images=$(grep -o '<img [^>]*src="[^"]*"' "$work/orbit_dom.html" |
  sed 's/.*src="\([^"]*\)"/\1/')
orbit_count=$(printf '%s\n' "$orbit_images" | grep -c . || true)
[ "$orbit_count" -eq 9 ] ||
  fail "expected 3 frames x 3 images in the temporal report, found $orbit_count"
while IFS= read -r src; do
  [ -f "$orbit/$src" ] || fail "temporal report: <img src=\"$src\"> but the file does not exist"
done <<<"$orbit_images"

# 3. screenshot
shot="$work/screenshot.png"
browser "$work/shot.out" "$work/shot.log" --window-size=1400,2400 --screenshot="$shot" "$url"
if grep -E 'CONSOLE|Uncaught|Failed to load resource|net::ERR_' "$work/shot.log"; then
  fail "console errors or failed loads while taking the screenshot"
fi
[ -f "$shot" ] || fail "no screenshot written"
size=$(wc -c <"$shot")
[ "$size" -gt 50000 ] || fail "screenshot is only $size bytes (blank page?)"
if command -v python3 >/dev/null 2>&1; then
  python3 - "$shot" <<'PY' || fail "screenshot looks blank"
# Decodes the PNG (8-bit RGB/RGBA, any filter) with zlib only and counts the distinct colours.
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
pos, idat = 8, b""
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    pos += 12 + n
    if kind == b"IHDR":
        width, height, depth, colour = struct.unpack(">IIBB", body[:10])
    elif kind == b"IDAT":
        idat += body
channels = {2: 3, 6: 4}[colour]
assert depth == 8
raw, stride = zlib.decompress(idat), width * channels
previous, colours, p = bytearray(stride), set(), 0
for y in range(height):
    f, line = raw[p], bytearray(raw[p + 1:p + 1 + stride])
    p += 1 + stride
    if f == 2:  # Up, by far the most common filter of a page screenshot: one pass in C
        line = bytearray((u + v) & 255 for u, v in zip(line, previous))
    elif f == 1:
        for x in range(channels, stride):
            line[x] = (line[x] + line[x - channels]) & 255
    elif f in (3, 4):
        for x in range(stride):
            a = line[x - channels] if x >= channels else 0
            b = previous[x]
            if f == 3:
                line[x] = (line[x] + ((a + b) >> 1)) & 255
                continue
            c = previous[x - channels] if x >= channels else 0
            pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
            line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    previous = line
    if y % 8 == 0:
        for x in range(0, stride, channels * 2):
            colours.add(bytes(line[x:x + 3]))
print(f"report_chromium_test: screenshot {width}x{height}, {len(colours)} distinct colours sampled")
sys.exit(0 if len(colours) >= 50 else 1)
PY
fi
if [ -n "${MFR_REPORT_SCREENSHOT:-}" ]; then cp "$shot" "$MFR_REPORT_SCREENSHOT"; fi
echo "report_chromium_test: PASS ($count images, $tables tables, $svgs plots, $fronts front" \
  "points, temporal report $orbit_svgs plots and $orbit_count images, screenshot $size bytes)"
