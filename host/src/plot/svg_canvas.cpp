#include "svg_canvas.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pathstream::host::plot::detail {
namespace {

constexpr double kFontSize = 12;

std::string px_text(double v) {
    return format_number(v, 1);
}

}  // namespace

std::string xml_escape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&apos;";
                break;
            default:
                // Control characters other than tab/newline are not allowed in XML 1.0.
                if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n') {
                    out += ' ';
                } else {
                    out += c;
                }
        }
    }
    return out;
}

std::string format_number(double value, int decimals) {
    if (!std::isfinite(value)) return "nan";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", std::max(0, decimals), value);
    std::string s = buf;
    if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
    return s;
}

Ticks nice_ticks(double lo, double hi, int target) {
    Ticks t;
    if (!(hi > lo)) {
        t.values = {lo};
        return t;
    }
    const double raw = (hi - lo) / std::max(1, target);
    const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    double step = magnitude;
    for (double m : {1.0, 2.0, 5.0, 10.0}) {
        step = m * magnitude;
        if (step >= raw) break;
    }
    t.decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
    for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) {
        t.values.push_back(std::fabs(v) < step * 1e-9 ? 0.0 : v);
    }
    return t;
}

const char* axis_colour(std::size_t axis) {
    static const char* const colours[] = {"#1f5fbf", "#c2255c", "#2b8a3e", "#e67700",
                                          "#6741d9", "#0b7285", "#5c940d", "#862e9c"};
    return colours[axis % 8];
}

Canvas::Canvas(double width, double height, double left, double top, double right, double bottom)
    : width_(width), height_(height), left_(left), top_(top), right_(right), bottom_(bottom) {}

void Canvas::set_range(double x0, double x1, double y0, double y1, bool y_down) {
    if (!(x1 > x0)) x1 = x0 + 1;
    if (!(y1 > y0)) y1 = y0 + 1;
    x0_ = x0;
    x1_ = x1;
    y0_ = y0;
    y1_ = y1;
    y_down_ = y_down;
    sx_ = plot_width() / (x1 - x0);
    sy_ = plot_height() / (y1 - y0);
}

void Canvas::title(const std::string& text) {
    title_ = text;
}

void Canvas::legend(const std::vector<LegendEntry>& entries) {
    legend_ = entries;
}

void Canvas::axes(const std::string& x_label, const std::string& y_label) {
    std::ostringstream& o = head_;
    const double l = left_, t = top_, w = plot_width(), h = plot_height();
    o << "<g id=\"axes\" stroke=\"#000\" stroke-width=\"1\">\n";
    const Ticks xt = nice_ticks(x0_, x1_, static_cast<int>(w / 90));
    const Ticks yt = nice_ticks(y0_, y1_, static_cast<int>(h / 60));
    for (double v : xt.values) {
        const double x = px(v);
        o << "<line x1=\"" << px_text(x) << "\" y1=\"" << px_text(t) << "\" x2=\"" << px_text(x)
          << "\" y2=\"" << px_text(t + h) << "\" stroke=\"#e6e6e6\"/>\n";
        o << "<line x1=\"" << px_text(x) << "\" y1=\"" << px_text(t + h) << "\" x2=\"" << px_text(x)
          << "\" y2=\"" << px_text(t + h + 5) << "\"/>\n";
        o << "<text class=\"tick-label\" x=\"" << px_text(x) << "\" y=\"" << px_text(t + h + 18)
          << "\" text-anchor=\"middle\" stroke=\"none\">" << format_number(v, xt.decimals)
          << "</text>\n";
    }
    for (double v : yt.values) {
        const double y = py(v);
        o << "<line x1=\"" << px_text(l) << "\" y1=\"" << px_text(y) << "\" x2=\"" << px_text(l + w)
          << "\" y2=\"" << px_text(y) << "\" stroke=\"#e6e6e6\"/>\n";
        o << "<line x1=\"" << px_text(l - 5) << "\" y1=\"" << px_text(y) << "\" x2=\"" << px_text(l)
          << "\" y2=\"" << px_text(y) << "\"/>\n";
        o << "<text class=\"tick-label\" x=\"" << px_text(l - 8) << "\" y=\"" << px_text(y + 4)
          << "\" text-anchor=\"end\" stroke=\"none\">" << format_number(v, yt.decimals)
          << "</text>\n";
    }
    o << "<text class=\"axis-title\" x=\"" << px_text(l + w / 2) << "\" y=\"" << px_text(t + h + 38)
      << "\" text-anchor=\"middle\" stroke=\"none\">" << xml_escape(x_label) << "</text>\n";
    o << "<text class=\"axis-title\" transform=\"translate(" << px_text(16) << ' '
      << px_text(t + h / 2) << ") rotate(-90)\" text-anchor=\"middle\" stroke=\"none\">"
      << xml_escape(y_label) << "</text>\n";
    o << "</g>\n";
}

void Canvas::begin_series(const std::string& id) {
    body_ << "<g id=\"" << xml_escape(id) << "\" clip-path=\"url(#plot-area)\" fill=\"none\">\n";
}

void Canvas::polyline(const std::vector<Point>& data, const std::string& colour, double width,
                      const std::string& dash, const std::string& cls) {
    std::vector<Point> pixels;
    pixels.reserve(data.size());
    for (const Point& p : data) pixels.push_back({px(p.x), py(p.y)});
    polyline_px(pixels, colour, width, dash, cls);
}

void Canvas::polyline_px(const std::vector<Point>& pixels, const std::string& colour, double width,
                         const std::string& dash, const std::string& cls) {
    if (pixels.empty()) return;
    std::ostringstream& o = body_;
    o << "<polyline";
    if (!cls.empty()) o << " class=\"" << xml_escape(cls) << '"';
    o << " stroke=\"" << colour << "\" stroke-width=\"" << format_number(width, 1)
      << "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"";
    if (!dash.empty()) o << " stroke-dasharray=\"" << dash << '"';
    o << " points=\"";
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        if (i) o << ' ';
        o << px_text(pixels[i].x) << ',' << px_text(pixels[i].y);
    }
    if (pixels.size() == 1) o << ' ' << px_text(pixels[0].x) << ',' << px_text(pixels[0].y);
    o << "\"/>\n";
}

void Canvas::hline(double y, const std::string& colour, const std::string& dash,
                   const std::string& id, const std::string& label) {
    const double yy = py(y);
    if (yy < top_ - 0.5 || yy > top_ + plot_height() + 0.5) return;
    body_ << "<line id=\"" << xml_escape(id) << "\" x1=\"" << px_text(left_) << "\" y1=\""
          << px_text(yy) << "\" x2=\"" << px_text(left_ + plot_width()) << "\" y2=\"" << px_text(yy)
          << "\" stroke=\"" << colour << "\" stroke-width=\"1.5\"";
    if (!dash.empty()) body_ << " stroke-dasharray=\"" << dash << '"';
    body_ << "/>\n";
    if (!label.empty()) {
        body_ << "<text x=\"" << px_text(left_ + plot_width() - 4) << "\" y=\"" << px_text(yy - 4)
              << "\" text-anchor=\"end\" fill=\"" << colour << "\" font-size=\"11\">"
              << xml_escape(label) << "</text>\n";
    }
}

void Canvas::band(double x_from, double x_to, const std::string& fill, const std::string& cls) {
    const double a = std::clamp(px(x_from), left_, left_ + plot_width());
    const double b = std::clamp(px(x_to), left_, left_ + plot_width());
    if (b - a <= 0) return;
    body_ << "<rect class=\"" << xml_escape(cls) << "\" x=\"" << px_text(a) << "\" y=\""
          << px_text(top_) << "\" width=\"" << px_text(std::max(b - a, 0.5)) << "\" height=\""
          << px_text(plot_height()) << "\" fill=\"" << fill << "\" stroke=\"none\"/>\n";
}

void Canvas::note(const std::string& text) {
    notes_.push_back(text);
}

std::string Canvas::finish() {
    // Legend rows (wrapped to the width) above the plot, note lines (wrapped) below it; the
    // plot moves down and the document grows by what does not fit the fixed margins.
    constexpr double kCharWidth = 6.8, kRow = 15;
    struct Placed {
        const LegendEntry* entry;
        double x, y;
    };
    std::vector<Placed> placed;
    double x = left_, y = 40;
    for (const LegendEntry& e : legend_) {
        const double w = 32 + kCharWidth * static_cast<double>(e.label.size()) + 20;
        if (x > left_ && x + w - 20 > width_ - right_) {
            x = left_;
            y += kRow;
        }
        placed.push_back({&e, x, y});
        x += w;
    }
    const double extra_top = y - 40;
    std::vector<std::string> note_lines;
    const auto max_chars = static_cast<std::size_t>(std::max(20.0, (width_ - 16) / 6.2));
    for (const std::string& n : notes_) {
        std::istringstream words(n);
        std::string line, word;
        while (words >> word) {
            if (!line.empty() && line.size() + 1 + word.size() > max_chars) {
                note_lines.push_back(line);
                line.clear();
            }
            line += (line.empty() ? "" : " ") + word;
        }
        if (!line.empty()) note_lines.push_back(line);
    }
    const double extra_bottom =
        note_lines.size() > 1 ? kRow * static_cast<double>(note_lines.size() - 1) : 0;
    const double height = height_ + extra_top + extra_bottom;

    std::ostringstream o;
    o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    o << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" << px_text(width_)
      << "\" height=\"" << px_text(height) << "\" viewBox=\"0 0 " << px_text(width_) << ' '
      << px_text(height) << "\" font-family=\"DejaVu Sans, Arial, sans-serif\" font-size=\""
      << kFontSize << "\">\n";
    o << "<defs><clipPath id=\"plot-area\"><rect x=\"" << px_text(left_) << "\" y=\""
      << px_text(top_) << "\" width=\"" << px_text(plot_width()) << "\" height=\""
      << px_text(plot_height()) << "\"/></clipPath></defs>\n";
    o << "<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n";
    if (!title_.empty()) {
        o << "<text id=\"title\" x=\"" << px_text(left_)
          << "\" y=\"20\" font-size=\"15\" font-weight=\"bold\">" << xml_escape(title_)
          << "</text>\n";
    }
    if (extra_top > 0)
        o << "<g id=\"plot\" transform=\"translate(0 " << px_text(extra_top) << ")\">\n";
    // Grid and labels first, series over them, the frame last (over any shading).
    o << head_.str();
    o << body_.str();
    o << "<rect id=\"frame\" x=\"" << px_text(left_) << "\" y=\"" << px_text(top_) << "\" width=\""
      << px_text(plot_width()) << "\" height=\"" << px_text(plot_height())
      << "\" fill=\"none\" stroke=\"#000\" stroke-width=\"1\"/>\n";
    if (extra_top > 0) o << "</g>\n";
    if (!placed.empty()) {
        o << "<g id=\"legend\">\n";
        for (const Placed& p : placed) {
            const LegendEntry& e = *p.entry;
            o << "<line x1=\"" << px_text(p.x) << "\" y1=\"" << px_text(p.y - 4) << "\" x2=\""
              << px_text(p.x + 26) << "\" y2=\"" << px_text(p.y - 4) << "\" stroke=\"" << e.colour
              << "\" stroke-width=\"" << format_number(e.width, 1) << '"';
            if (!e.dash.empty()) o << " stroke-dasharray=\"" << e.dash << '"';
            o << "/>\n";
            o << "<text x=\"" << px_text(p.x + 32) << "\" y=\"" << px_text(p.y) << "\">"
              << xml_escape(e.label) << "</text>\n";
        }
        o << "</g>\n";
    }
    double ny = height_ + extra_top - 8;
    for (const std::string& n : note_lines) {
        o << "<text class=\"note\" x=\"8\" y=\"" << px_text(ny)
          << "\" font-size=\"11\" fill=\"#555\">" << xml_escape(n) << "</text>\n";
        ny += kRow;
    }
    o << "</svg>\n";
    return o.str();
}

}  // namespace pathstream::host::plot::detail
