#pragma once
// The simulated time burnt into a scene camera's frames ("t = 12.345 s", top left), so that a
// picture or a video says when it shows (RenderSettings::time_stamp).

#include <ssx/render.hpp>
#include <ssx/types.hpp>

#include <string>

namespace ssx::detail {

/// "t = 12.345 s": the time in seconds with three decimals (a millisecond).
std::string timeStampText(Nanoseconds time);

/// Writes timeStampText(time) into the top-left corner of `image`: white letters on a darkened
/// box, scaled with the image (2 pixels per font pixel at 480 rows), clipped to the image.
void stampTime(Image& image, Nanoseconds time);

}  // namespace ssx::detail
