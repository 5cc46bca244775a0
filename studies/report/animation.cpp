// The linkage animated in SVG with SMIL: each shape's static attributes hold its first frame and
// an <animate> element per attribute runs through every frame, looping.
#include "studies/report/animation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "studies/report/report_support.hpp"

namespace bd::studies::report_support {

namespace {

// model coordinates [m] to the picture's pixels: equal axes, y up
struct View {
  double x0{}, y1{}, k = 1, pad = 30;
  double X(double x) const { return pad + (x - x0) * k; }
  double Y(double y) const { return pad + (y1 - y) * k; }
};

std::string px(double v) { return fmt(v, "%.1f"); }

std::string points_text(const View& v, const std::vector<Vec2>& pts, bool closed) {
  std::string s;
  for (const Vec2& p : pts) s += (s.empty() ? "" : " ") + px(v.X(p.x())) + "," + px(v.Y(p.y()));
  if (closed && !pts.empty()) s += " " + px(v.X(pts[0].x())) + "," + px(v.Y(pts[0].y()));
  return s;
}

std::string animate(const std::string& attribute, const std::vector<std::string>& values,
                    double seconds) {
  std::string s = "<animate attributeName=\"" + attribute + "\" dur=\"" + fmt(seconds, "%.3g") +
                  "s\" repeatCount=\"indefinite\" calcMode=\"linear\" values=\"";
  for (std::size_t i = 0; i < values.size(); ++i) s += (i ? ";" : "") + values[i];
  return s + "\"/>";
}

// a nice length for the scale bar: 1, 2 or 5 times a power of ten, about a fifth of `span`
double scale_bar(double span) {
  const double target = span / 5, p = std::pow(10.0, std::floor(std::log10(target)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * p <= target) return m * p;
  return p;
}

}  // namespace

std::vector<std::size_t> frame_indices(std::size_t first, std::size_t last, std::size_t count) {
  std::vector<std::size_t> out;
  if (last < first || count == 0) return out;
  const std::size_t n = last - first + 1;
  if (n <= count) {
    for (std::size_t i = first; i <= last; ++i) out.push_back(i);
    return out;
  }
  for (std::size_t k = 0; k < count; ++k) {
    out.push_back(first + (count == 1 ? 0 : k * (n - 1) / (count - 1)));
  }
  return out;
}

std::string animation_svg(const Animation& a) {
  // the bounds of every point of every frame
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const AnimatedShape& s : a.shapes) {
    for (const auto& frame : s.frames) {
      for (const Vec2& p : frame) {
        if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
        x0 = std::min(x0, p.x());
        x1 = std::max(x1, p.x());
        y0 = std::min(y0, p.y());
        y1 = std::max(y1, p.y());
      }
    }
  }
  if (!(x1 >= x0)) x0 = x1 = y0 = y1 = 0;
  const double span = std::max({x1 - x0, y1 - y0, 1e-6});
  // equal axes: the scale that fits the width (900 px) and a height of at most 640 px
  View v;
  const double width = 900, inner_w = width - 2 * v.pad, inner_h = 640 - 2 * v.pad - 30;
  const double w = std::max(x1 - x0, 0.05 * span), hgt = std::max(y1 - y0, 0.05 * span);
  v.k = std::min(inner_w / w, inner_h / hgt);
  v.x0 = 0.5 * (x0 + x1) - 0.5 * inner_w / v.k;  // centred
  v.y1 = y1;
  const double height = hgt * v.k + 2 * v.pad + 30;
  std::string h = "<svg class=\"animation\" id=\"" + esc(a.id) +
                  "\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " + px(width) + " " +
                  px(height) + "\" role=\"img\" aria-label=\"" + esc(a.id) + "\">\n";
  h += "<rect x=\"0\" y=\"0\" width=\"" + px(width) + "\" height=\"" + px(height) +
       "\" fill=\"white\"/>\n";
  for (const AnimatedShape& s : a.shapes) {
    if (s.frames.empty()) continue;
    const bool moves = s.frames.size() > 1;
    const std::string title = s.title.empty() ? "" : "<title>" + esc(s.title) + "</title>";
    if (s.kind == AnimatedShape::Kind::kLine) {
      h += "<polyline fill=\"none\" stroke=\"" + s.colour + "\" stroke-width=\"" + px(s.size) +
           "\" stroke-linecap=\"round\" stroke-linejoin=\"round\"" +
           (s.dashed ? " stroke-dasharray=\"6 4\"" : "") + " points=\"" +
           points_text(v, s.frames[0], s.closed) + "\">" + title;
      if (moves) {
        std::vector<std::string> values;
        for (const auto& f : s.frames) values.push_back(points_text(v, f, s.closed));
        h += animate("points", values, a.seconds);
      }
      h += "</polyline>\n";
      continue;
    }
    const Vec2 p = s.frames[0].empty() ? Vec2(0, 0) : s.frames[0][0];
    if (s.kind == AnimatedShape::Kind::kGround) {  // a triangle under the joint, hatched base
      const double X = v.X(p.x()), Y = v.Y(p.y()), r = s.size;
      h += "<g>" + title +
           "<polygon fill=\"#d8d8d8\" stroke=\"#404040\" stroke-width=\"1.5\" points=\"" + px(X) +
           "," + px(Y) + " " + px(X - r) + "," + px(Y + 1.6 * r) + " " + px(X + r) + "," +
           px(Y + 1.6 * r) + "\"/><circle cx=\"" + px(X) + "\" cy=\"" + px(Y) +
           "\" r=\"3.5\" fill=\"white\" stroke=\"#404040\" stroke-width=\"1.5\"/></g>\n";
      continue;
    }
    h += "<circle cx=\"" + px(v.X(p.x())) + "\" cy=\"" + px(v.Y(p.y())) + "\" r=\"" + px(s.size) +
         "\" fill=\"" + s.colour + "\" stroke=\"#202020\" stroke-width=\"1\">" + title;
    if (moves) {
      std::vector<std::string> xs, ys;
      for (const auto& f : s.frames) {
        const Vec2 q = f.empty() ? p : f[0];
        xs.push_back(px(v.X(q.x())));
        ys.push_back(px(v.Y(q.y())));
      }
      h += animate("cx", xs, a.seconds) + animate("cy", ys, a.seconds);
    }
    h += "</circle>\n";
  }
  for (const AnimatedLabel& l : a.labels) {
    h += "<text x=\"" + px(v.X(l.at.x()) + 8) + "\" y=\"" + px(v.Y(l.at.y()) + 22) +
         "\" font-family=\"sans-serif\" font-size=\"13\" fill=\"#303030\">" + esc(l.text) +
         "</text>\n";
  }
  // the scale bar, bottom left
  const double bar = scale_bar(span);
  const double by = height - 12, bx = v.pad;
  h += "<g font-family=\"sans-serif\" font-size=\"12\" fill=\"#303030\"><line x1=\"" + px(bx) +
       "\" y1=\"" + px(by) + "\" x2=\"" + px(bx + bar * v.k) + "\" y2=\"" + px(by) +
       "\" stroke=\"#303030\" stroke-width=\"2\"/><text x=\"" + px(bx + bar * v.k + 6) + "\" y=\"" +
       px(by + 4) + "\">" + fmt(bar, "%g") + " m</text></g>\n";
  return h + "</svg>";
}

}  // namespace bd::studies::report_support
