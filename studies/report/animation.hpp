#pragma once
/// The linkage animated on the report page: an inline SVG whose shapes move by SMIL <animate>
/// elements (no script), looping over the frames given. Its static attributes are the first
/// frame, so a printed page or a viewer without animation shows the linkage still, in its first
/// pose. Internal to bd_studies.
#include <string>
#include <vector>

#include "core/types.hpp"

namespace bd::studies::report_support {

/// One thing drawn: a line through points (a link), a dot (a joint, a counterweight, a centre of
/// mass) or a ground mark, with its place in every frame (a shape that does not move may give
/// one frame).
struct AnimatedShape {
  enum class Kind { kLine, kDot, kGround };
  Kind kind = Kind::kLine;
  std::string colour = "#1f4e99";
  double size = 3;    // line width or dot radius [px]
  bool closed{};      // a line: back to its first point (a ternary link's outline)
  bool dashed{};      // a line: dashed (a frame guide, a counterweight's arm)
  std::string title;  // shown on hover
  std::vector<std::vector<Vec2>> frames;  // per frame its points [m] (a dot or a mark: one)
};

/// A text at a fixed place [m] (a ground joint's name).
struct AnimatedLabel {
  Vec2 at{0, 0};
  std::string text;
};

struct Animation {
  std::string id;                     // unique on the page
  double seconds = 4;                 // one pass over the frames
  std::vector<AnimatedShape> shapes;  // drawn in order
  std::vector<AnimatedLabel> labels;
};

/// The animation as inline SVG (900 px wide, equal axes, y up), with a scale bar in metres.
/// Frames that return to the first (a driven revolution given with its periodic end) loop
/// without a jump.
std::string animation_svg(const Animation& animation);

/// `count` indices spread evenly over [first, last] (both included; fewer when the range is
/// shorter).
std::vector<std::size_t> frame_indices(std::size_t first, std::size_t last, std::size_t count);

}  // namespace bd::studies::report_support
