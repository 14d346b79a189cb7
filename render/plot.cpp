#include "render/plot.h"

#include "render/text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace flexure::render {

std::vector<double> niceTicks(double lo, double hi, int target) {
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return {lo};
  const double raw = (hi - lo) / std::max(target, 1);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  // The candidate step whose tick count is closest to the target (fewer ticks on a tie).
  double step = 10 * p;
  double best = 1e300;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    const double count = std::floor(hi / (m * p) + 1e-9) - std::ceil(lo / (m * p) - 1e-9) + 1;
    const double miss = std::abs(count - target) - 1e-3 * m;
    if (miss < best) best = miss, step = m * p;
  }
  std::vector<double> ticks;
  const long long first = static_cast<long long>(std::ceil(lo / step - 1e-9));
  const long long last = static_cast<long long>(std::floor(hi / step + 1e-9));
  for (long long k = first; k <= last && ticks.size() < 100; ++k) ticks.push_back(static_cast<double>(k) * step);
  return ticks;
}

std::vector<std::string> tickLabels(const std::vector<double>& ticks) {
  std::vector<std::string> out;
  for (int decimals = 0; decimals <= 12; ++decimals) {
    out.clear();
    bool distinct = true;
    for (size_t i = 0; i < ticks.size(); ++i) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.*f", decimals, ticks[i]);
      std::string text = buf;
      if (text.find_first_not_of("-0.") == std::string::npos) text = "0";
      // Ticks are multiples of the step: equal text means too few decimals.
      if (!out.empty() && text == out.back()) distinct = false;
      if (std::abs(std::strtod(buf, nullptr) - ticks[i]) > 1e-9 * std::max(1.0, std::abs(ticks[i]))) distinct = false;
      out.push_back(text);
    }
    if (distinct) break;
  }
  return out;
}

namespace {

Point3 at(double x, double y) { return {x, y, 0}; }

// Text width estimate (DejaVu Sans averages about 0.6 em per character), for layout only.
double textWidth(const std::string& text, double size) { return 0.6 * size * static_cast<double>(utf8Characters(text)); }

}  // namespace

PlotCanvas::PlotCanvas(Plot plot, PlotStyle style) : plot_(std::move(plot)), style_(style) {
  const double W = style_.width, H = style_.height;
  s_ = style_.unit_px > 0 ? style_.unit_px : std::min(W, H) / 1000.0;
  const double s = s_;
  const double t = style_.unit_px > 0 ? s : std::max(s, 0.45);  // text and margins: still legible in small plots

  // Data bounds over everything drawn.
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  auto include = [&](const Point2& p) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) return;
    xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
    ymin = std::min(ymin, p[1]), ymax = std::max(ymax, p[1]);
  };
  for (const auto& ser : plot_.series)
    for (const auto& p : ser.points) include(p);
  for (const auto& a : plot_.arrows) include(a.from), include(a.to);
  if (plot_.start) include(*plot_.start);
  if (!(xmax >= xmin)) xmin = ymin = -1, xmax = ymax = 1;
  double span = std::max(xmax - xmin, ymax - ymin);
  if (!(span > 0)) span = std::max({1.0, std::abs(xmin), std::abs(ymin)}) * 1e-3;
  const double pad = 0.06 * span + 0.0;
  lo_ = {xmin - pad, ymin - pad};
  hi_ = {xmax + pad, ymax + pad};
  if (hi_[0] - lo_[0] < 1e-3 * span) lo_[0] -= 0.5 * span, hi_[0] += 0.5 * span;
  if (hi_[1] - lo_[1] < 1e-3 * span) lo_[1] -= 0.5 * span, hi_[1] += 0.5 * span;

  // The frame: room for tick labels on the left, the x label below, title and y label on top,
  // the legend (with two or more entries) on the right.
  int legend_entries = 0;
  double legend_w = 0;
  for (const auto& ser : plot_.series)
    if (!ser.label.empty()) ++legend_entries, legend_w = std::max(legend_w, textWidth(ser.label, style_.tick_font_size * t));
  const bool legend = legend_entries >= 2;
  const double tick_font = style_.tick_font_size * t, title_font = style_.font_size * t;
  x0_ = 150 * t;
  x1_ = W - (legend ? 70 * t + 60 * t + legend_w : 50 * t);
  y0_ = 120 * t;
  const int heading_lines = !plot_.title.empty() + !plot_.subtitle.empty();
  y1_ = H - (heading_lines == 0 ? 70 : heading_lines == 1 ? 120 : 150) * t;
  if (x1_ - x0_ < 20 || y1_ - y0_ < 20) x0_ = 0.1 * W, x1_ = 0.9 * W, y0_ = 0.1 * H, y1_ = 0.9 * H;

  if (style_.equal_aspect) {  // the same units per pixel on both axes
    const double upp = std::max((hi_[0] - lo_[0]) / (x1_ - x0_), (hi_[1] - lo_[1]) / (y1_ - y0_));
    const double cx = 0.5 * (lo_[0] + hi_[0]), cy = 0.5 * (lo_[1] + hi_[1]);
    lo_ = {cx - 0.5 * upp * (x1_ - x0_), cy - 0.5 * upp * (y1_ - y0_)};
    hi_ = {cx + 0.5 * upp * (x1_ - x0_), cy + 0.5 * upp * (y1_ - y0_)};
  }
  xticks_ = niceTicks(lo_[0], hi_[0], std::max(3, static_cast<int>((x1_ - x0_) / (140 * t))));
  yticks_ = niceTicks(lo_[1], hi_[1], std::max(3, static_cast<int>((y1_ - y0_) / (110 * t))));

  // Everything that does not move.
  DrawList& d = fixed_;
  const float thin = static_cast<float>(std::max(1.0, 1.5 * s)), frame_w = static_cast<float>(std::max(1.0, 2.5 * s));
  for (double tick : xticks_) {
    const double x = toPixels({tick, lo_[1]})[0];
    d.segment(at(x, y0_), at(x, y1_), thin, style_.grid_color);
  }
  for (double tick : yticks_) {
    const double y = toPixels({lo_[0], tick})[1];
    d.segment(at(x0_, y), at(x1_, y), thin, style_.grid_color);
  }
  const double tick_len = 10 * t;
  const auto xl = tickLabels(xticks_), yl = tickLabels(yticks_);
  for (size_t i = 0; i < xticks_.size(); ++i) {
    const double x = toPixels({xticks_[i], lo_[1]})[0];
    d.segment(at(x, y0_), at(x, y0_ - tick_len), frame_w, style_.axis_color);
    Label l;
    l.at = at(x, y0_ - tick_len - 8 * t - 0.5 * tick_font);
    l.text = xl[i], l.size = static_cast<float>(tick_font), l.color = style_.axis_color, l.regular = true;
    d.labels.push_back(l);
  }
  for (size_t i = 0; i < yticks_.size(); ++i) {
    const double y = toPixels({lo_[0], yticks_[i]})[1];
    d.segment(at(x0_, y), at(x0_ - tick_len, y), frame_w, style_.axis_color);
    Label l;
    l.at = at(x0_ - tick_len - 8 * t, y);
    l.text = yl[i], l.size = static_cast<float>(tick_font), l.color = style_.axis_color, l.regular = true, l.align = 1;
    d.labels.push_back(l);
  }
  for (const auto& [a, b] : {std::pair{at(x0_, y0_), at(x1_, y0_)}, {at(x1_, y0_), at(x1_, y1_)},
                             {at(x1_, y1_), at(x0_, y1_)}, {at(x0_, y1_), at(x0_, y0_)}})
    d.segment(a, b, frame_w, style_.axis_color);
  if (!plot_.xlabel.empty()) {
    Label l;
    l.at = at(0.5 * (x0_ + x1_), y0_ - tick_len - 18 * t - 1.6 * tick_font);
    l.text = plot_.xlabel, l.size = static_cast<float>(tick_font), l.color = style_.axis_color, l.regular = true;
    d.labels.push_back(l);
  }
  if (!plot_.ylabel.empty()) {
    Label l;
    l.at = at(x0_, y1_ + 12 * t + 0.5 * tick_font);
    l.text = plot_.ylabel, l.size = static_cast<float>(tick_font), l.color = style_.axis_color, l.regular = true,
    l.align = -1;
    d.labels.push_back(l);
  }
  // Title and subtitle centred over the frame, smaller when they would not fit the image.
  auto fitted = [&](const std::string& text, double size) {
    return std::min(size, 0.94 * W / std::max(1.0, 0.65 * static_cast<double>(utf8Characters(text))));
  };
  if (!plot_.title.empty()) {
    Label l;
    l.at = at(0.5 * W, H - 40 * t);
    l.text = plot_.title, l.size = static_cast<float>(fitted(plot_.title, title_font)), l.color = style_.axis_color;
    d.labels.push_back(l);
  }
  if (!plot_.subtitle.empty()) {
    Label l;
    l.at = at(0.5 * W, H - (plot_.title.empty() ? 40 : 78) * t);
    l.text = plot_.subtitle, l.size = static_cast<float>(fitted(plot_.subtitle, tick_font)), l.regular = true;
    l.color = style_.axis_color;
    d.labels.push_back(l);
  }

  // Curves, then marks, arrows and the start on top.
  const float line = static_cast<float>(style_.line_width * s);
  for (const auto& ser : plot_.series) {
    for (size_t i = 1; i < ser.points.size(); ++i) {
      const Point2 a = toPixels(ser.points[i - 1]), b = toPixels(ser.points[i]);
      d.segment(at(a[0], a[1]), at(b[0], b[1]), line, ser.color);
    }
    if (ser.points.size() == 1) {
      const Point2 a = toPixels(ser.points[0]);
      d.disc(at(a[0], a[1]), 0.5f * line, ser.color);
    }
  }
  const float mark_r = static_cast<float>(0.3 * style_.marker_size * s);
  for (const auto& ser : plot_.series)
    for (int i : ser.marks)
      if (i >= 0 && i < static_cast<int>(ser.points.size())) {
        const Point2 a = toPixels(ser.points[static_cast<size_t>(i)]);
        d.disc(at(a[0], a[1]), mark_r, style_.mark_color, static_cast<float>(std::max(1.0, 2 * s)), Color{0, 0, 0, 1});
      }
  for (const auto& ar : plot_.arrows) {
    const Point2 a = toPixels(ar.from), b = toPixels(ar.to);
    d.arrow(at(a[0], a[1]), at(b[0], b[1]), 0.6f * line, static_cast<float>(style_.arrow_size * s), ar.color);
  }
  if (plot_.start) {
    const Point2 a = toPixels(*plot_.start);
    Shape p;
    p.kind = ShapeKind::Pentagon;
    p.a = p.b = at(a[0], a[1]);
    p.radius = static_cast<float>(0.5 * style_.marker_size * s);
    p.fill = style_.start_color;
    p.outline = static_cast<float>(std::max(1.0, 1.5 * s));
    p.stroke = Color{0, 0, 0, 1};
    p.pointing[0] = 0, p.pointing[1] = 1;
    d.shapes.push_back(p);
  }
  if (legend) {
    double y = y1_ - 20 * t - 0.5 * tick_font;
    const double lx = x1_ + 40 * t;
    for (const auto& ser : plot_.series) {
      if (ser.label.empty()) continue;
      d.segment(at(lx, y), at(lx + 50 * t, y), line, ser.color);
      Label l;
      l.at = at(lx + 65 * t, y);
      l.text = ser.label, l.size = static_cast<float>(tick_font), l.color = style_.axis_color, l.regular = true,
      l.align = -1;
      d.labels.push_back(l);
      y -= 1.8 * tick_font;
    }
  }
}

Point2 PlotCanvas::toPixels(const Point2& p) const {
  return {x0_ + (p[0] - lo_[0]) / (hi_[0] - lo_[0]) * (x1_ - x0_), y0_ + (p[1] - lo_[1]) / (hi_[1] - lo_[1]) * (y1_ - y0_)};
}

View PlotCanvas::view() const {
  View v;
  v.width = style_.width, v.height = style_.height;
  v.background = style_.background;
  v.lo = {0, 0, 0};
  v.hi = {static_cast<double>(style_.width), static_cast<double>(style_.height), 0};
  return v;
}

DrawList PlotCanvas::draw(const std::optional<Point2>& cursor) const {
  DrawList d = fixed_;
  if (cursor) {
    const Point2 a = toPixels(*cursor);
    d.disc(at(a[0], a[1]), static_cast<float>(0.35 * style_.marker_size * s_), style_.cursor_color,
           static_cast<float>(std::max(1.0, 2.5 * s_)), Color{1, 1, 1, 1});
  }
  return d;
}

}  // namespace flexure::render
