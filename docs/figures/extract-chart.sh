# Sourced by the figure scripts (needs $tmp, a scratch folder).
# extract_chart PAGE ID FILE: the chart `ID` of a report.html, as the page draws it, written as a
# standalone SVG file (the page inlines it without an XML prolog or a size)
extract_chart() {
  awk -v id="id=\"chart-$2\"" '
    index($0, id) { found = 1; next }
    found && /^<svg/ { inside = 1 }
    inside { print }
    inside && /<\/svg>/ { exit }' "$1" >"$tmp/chart.svg"
  if ! grep -q '</svg>' "$tmp/chart.svg"; then
    echo "$(basename "$0"): $1 has no chart $2" >&2
    exit 1
  fi
  local size
  size=$(grep -o -m1 'viewBox="0 0 [0-9]* [0-9]*"' "$tmp/chart.svg" | tr -d '"' | cut -d' ' -f3,4)
  {
    echo '<?xml version="1.0" encoding="utf-8" standalone="no"?>'
    sed "1s|^<svg role=\"img\" aria-label=\"[^\"]*\"|<svg width=\"${size% *}\" height=\"${size#* }\"|" \
      "$tmp/chart.svg"
  } >"$3"
}

# extract_animation PAGE ID FILE: the linkage animation `ID` (original, balanced, optimized) of a
# report.html, an SVG that moves by SMIL, written as a standalone SVG file
extract_animation() {
  awk -v id="<svg class=\"animation\" id=\"animation-$2\"" '
    index($0, id) == 1 { inside = 1 }
    inside { print }
    inside && /<\/svg>/ { exit }' "$1" >"$tmp/animation.svg"
  if ! grep -q '</svg>' "$tmp/animation.svg"; then
    echo "$(basename "$0"): $1 has no animation $2" >&2
    exit 1
  fi
  local size
  size=$(grep -o -m1 'viewBox="0 0 [0-9.]* [0-9.]*"' "$tmp/animation.svg" | tr -d '"' | cut -d' ' -f3,4)
  {
    echo '<?xml version="1.0" encoding="utf-8" standalone="no"?>'
    sed "1s|^<svg class=\"animation\"|<svg width=\"${size% *}\" height=\"${size#* }\"|" \
      "$tmp/animation.svg"
  } >"$3"
}
