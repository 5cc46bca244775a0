# Sourced by the figure scripts (needs $tmp, a scratch folder).

# standalone PIECE OPENING FILE: the <svg> PIECE cut from a page (its first line starts with
# OPENING, the page's inline opening), written as a standalone SVG file with its size
standalone() {
  if ! grep -q '</svg>' "$1"; then
    return 1
  fi
  local size
  size=$(grep -o -m1 'viewBox="0 0 [0-9.]* [0-9.]*"' "$1" | tr -d '"' | cut -d' ' -f3,4)
  {
    echo '<?xml version="1.0" encoding="utf-8" standalone="no"?>'
    sed "1s|^$2|<svg width=\"${size% *}\" height=\"${size#* }\"|" "$1"
  } >"$3"
}

# extract_chart PAGE ID FILE: the chart `ID` of a report.html, as the page draws it, written as a
# standalone SVG file (the page inlines it without an XML prolog or a size)
extract_chart() {
  awk -v id="id=\"chart-$2\"" '
    index($0, id) { found = 1; next }
    found && /^<svg/ { inside = 1 }
    inside { print }
    inside && /<\/svg>/ { exit }' "$1" >"$tmp/chart.svg"
  standalone "$tmp/chart.svg" '<svg role="img" aria-label="[^"]*"' "$3" || {
    echo "$(basename "$0"): $1 has no chart $2" >&2
    exit 1
  }
}

# extract_animation PAGE ID FILE: the linkage animation `ID` (original, balanced, optimized) of a
# report.html, an SVG that moves by SMIL, written as a standalone SVG file
extract_animation() {
  awk -v id="<svg class=\"animation\" id=\"animation-$2\"" '
    index($0, id) == 1 { inside = 1 }
    inside { print }
    inside && /<\/svg>/ { exit }' "$1" >"$tmp/animation.svg"
  standalone "$tmp/animation.svg" '<svg class="animation"' "$3" || {
    echo "$(basename "$0"): $1 has no animation $2" >&2
    exit 1
  }
}
