// The SVG document walk: XML, elements, attributes and their places, units and transforms.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <pugixml.hpp>
#include <sstream>
#include <unordered_map>

#include "pathstream/host/svg_clip.hpp"
#include "pathstream/host/svg_path.hpp"
#include "pathstream/host/svg_warnings.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {
namespace {

using svg::Affine;
using svg::CubicSubpaths;
using svg::Point;

constexpr double kMaxCoordinateMm = 1e6;  // as the JSON reader: catches unit mix-ups
constexpr double kDegenerateMm = 1e-9;    // pieces smaller than this are dropped
constexpr std::size_t kMaxUses = 100000;  // <use> copies per document: stops exponential nesting
// Elements nested within one another, <use> targets included: far beyond what drawing programs
// write, and well within the stack (the walk recurses once per level).
constexpr std::size_t kMaxDepth = 500;
// Curve pieces a document may expand to: a base plus 16 per byte of the file, so that copies
// (<use>) cannot turn a small file into unbounded geometry (about 200 bytes of memory a piece).
constexpr std::size_t kPiecesBase = 250000;
constexpr std::size_t kPiecesPerByte = 16;
// Steps of clipping (segments flattened, grid cells visited, edges tested): a base plus 64 per
// byte, so that a huge hatch against a finely flattened clip ends in an error, not a long run.
constexpr std::uint64_t kClipWorkBase = 20000000;
constexpr std::uint64_t kClipWorkPerByte = 64;
// clipPath elements clipped by further clipPath elements, one within the other.
constexpr std::size_t kMaxClipChain = 16;
// The languages of systemLanguage tests the reader accepts (docs/formats-svg.md).
constexpr const char* kReaderLanguage = "en";
constexpr double kMmPerPx = 25.4 / 96.0;
constexpr double kNoBase = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kNoLayer = static_cast<std::size_t>(-1);
constexpr const char* kSvgNamespace = "http://www.w3.org/2000/svg";

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f';
}

std::string trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return std::string(s);
}

std::string lower(std::string s) {
    for (char& c : s) {
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    }
    return s;
}

std::string number_text(double v, int precision = 6) {
    std::ostringstream o;
    o.precision(precision);
    o << v;
    return o.str();
}

// What the walk carries down the tree.
struct State {
    Affine to_mm;            // user units of this element -> mm
    double width = kNoBase;  // viewport size in user units, for percentages
    double height = kNoBase;
    bool visible = true;           // inherited 'visibility'
    std::string stroke = "none";   // inherited 'stroke', kept for SvgReadInfo::strokes
    std::size_t layer = kNoLayer;  // the Inkscape layer the element is in (index in layers_)
};

// One property's cascaded value: from a presentation attribute, or from CSS (a <style> rule or
// the style attribute) with the byte offset of the declaration, for error places.
struct Cascaded {
    std::string value;
    bool set = false;
    bool css = false;
    std::size_t offset = 0;
};

// The properties the reader uses, after the cascade.
struct Style {
    Cascaded display, visibility, stroke, transform, origin;
    Cascaded clip_path, clip_rule, overflow;
    Cascaded mask, filter, marker, marker_start, marker_mid, marker_end, fill;  // warnings only
};

using ClipRegions = std::vector<std::shared_ptr<const svg::ClipRegion>>;

class Reader {
public:
    Reader(const std::string& text, const std::string& file, double tolerance_mm)
        : text_(text), file_(file), tolerance_mm_(tolerance_mm), locator_(text) {}

    Path read(svg::SvgReadInfo* info) {
        Path path = read();
        if (info) {
            info->strokes = strokes_;
            info->style_rules = sheet_.rules();
            info->location_bytes_scanned = locator_.bytes_scanned();
            info->locations = locator_.lookups();
            info->warnings = warnings_.lines(file_);
        }
        return path;
    }

private:
    Path read() {
        const pugi::xml_parse_result result =
            doc_.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
        if (!result) {
            std::string what = result.description();
            if (!what.empty() && what[0] >= 'A' && what[0] <= 'Z')
                what[0] = static_cast<char>(what[0] - 'A' + 'a');
            throw InputError(file_, locate(static_cast<std::size_t>(result.offset)),
                             "invalid XML: " + what);
        }
        const pugi::xml_node root = doc_.document_element();
        if (svg_name(root) != "svg") {
            throw InputError(file_, element_location(root),
                             "root element is <" + std::string(root.name()) + ">, expected <svg>");
        }
        style_sheets(root);
        root_svg(root);
        if (path_.subpaths.empty())
            throw InputError(file_, element_location(root), "no drawable paths");
        path_.axes = 2;
        assign_layers();
        return std::move(path_);
    }

    // ---- layers ----------------------------------------------------------------------------

    // Inkscape layers when the drawing has any (drawn content outside them goes to a layer of
    // its own, first); else one layer per stroke colour when there are several; else none.
    void assign_layers() {
        bool outside = false;
        for (std::size_t i = 0; i < path_.subpaths.size(); ++i)
            outside = outside || subpath_layers_[i] == kNoLayer;
        if (!layers_.empty()) {
            const std::size_t shift = outside ? 1 : 0;
            if (outside) path_.layers.push_back({"(outside layers)", {}, 0, ""});
            for (PathLayer& l : layers_) path_.layers.push_back(std::move(l));
            for (std::size_t i = 0; i < path_.subpaths.size(); ++i) {
                path_.subpaths[i].layer =
                    subpath_layers_[i] == kNoLayer ? 0 : subpath_layers_[i] + shift;
                const std::string colour = normal_colour(strokes_[i]);
                std::string& pen = path_.layers[path_.subpaths[i].layer].pen;
                if (colour == "none") continue;
                pen = pen.empty() || pen == colour ? colour : "mixed";
            }
            return;
        }
        std::vector<std::string> colours;
        for (std::size_t i = 0; i < path_.subpaths.size(); ++i) {
            const std::string colour = normal_colour(strokes_[i]);
            const auto at = std::find(colours.begin(), colours.end(), colour);
            path_.subpaths[i].layer = static_cast<std::size_t>(at - colours.begin());
            if (at == colours.end()) {
                colours.push_back(colour);
                path_.layers.push_back(
                    {colour, path_.subpaths[i].location, 0, colour == "none" ? "" : colour});
            }
        }
        if (colours.size() < 2) {
            path_.layers.clear();
            for (Subpath& s : path_.subpaths) s.layer = 0;
        }
    }

    // One spelling per colour: lower case, #rgb as #rrggbb, CSS's basic colour names as hex.
    static std::string normal_colour(std::string c) {
        c = lower(trim(c));
        if (c.size() == 4 && c[0] == '#')
            c = std::string("#") + c[1] + c[1] + c[2] + c[2] + c[3] + c[3];
        static const std::pair<const char*, const char*> kNamed[] = {
            {"black", "#000000"},   {"silver", "#c0c0c0"}, {"gray", "#808080"},
            {"grey", "#808080"},    {"white", "#ffffff"},  {"maroon", "#800000"},
            {"red", "#ff0000"},     {"purple", "#800080"}, {"fuchsia", "#ff00ff"},
            {"magenta", "#ff00ff"}, {"green", "#008000"},  {"lime", "#00ff00"},
            {"olive", "#808000"},   {"yellow", "#ffff00"}, {"navy", "#000080"},
            {"blue", "#0000ff"},    {"teal", "#008080"},   {"aqua", "#00ffff"},
            {"cyan", "#00ffff"},    {"orange", "#ffa500"}};
        for (const auto& [name, hex] : kNamed)
            if (c == name) return hex;
        return c.empty() ? "none" : c;
    }

    // A top-level Inkscape layer (<g inkscape:groupmode="layer">; sublayers belong to theirs):
    // named by its label, else its id, else its number.
    void enter_layer(pugi::xml_node n, State& state) {
        if (state.layer != kNoLayer ||
            std::string(n.attribute("inkscape:groupmode").value()) != "layer")
            return;
        std::string name = trim(n.attribute("inkscape:label").value());
        if (name.empty()) name = trim(n.attribute("id").value());
        if (name.empty()) name = std::to_string(layers_.size() + 1);
        state.layer = layers_.size();
        layers_.push_back({name, element_location(n), 0, ""});
    }

    // ---- places ----------------------------------------------------------------------------

    // Line and column (1-based, columns in characters of UTF-8) of a byte offset.
    SourceLocation locate(std::size_t offset) const { return locator_.locate(offset); }

    // Byte offset of an element's '<' (pugixml gives the offset of its name).
    std::size_t element_offset(pugi::xml_node n) const {
        const std::ptrdiff_t name = n.offset_debug();
        return name > 0 ? static_cast<std::size_t>(name - 1) : 0;
    }

    SourceLocation element_location(pugi::xml_node n) const { return locate(element_offset(n)); }

    // Where an attribute's name starts in the element's start tag; the element if not found.
    SourceLocation attribute_location(pugi::xml_node n, const char* name) const {
        return locate(attribute_offsets(n, name).first);
    }

    // Byte offsets of an attribute's name and of its value's first character in the start
    // tag; the element's '<' for both if not found.
    std::pair<std::size_t, std::size_t> attribute_offsets(pugi::xml_node n,
                                                          const char* name) const {
        const std::string_view t = text_;
        const std::size_t start = element_offset(n);
        std::size_t i = start + 1;
        const auto stop = [&](char c) { return is_space(c) || c == '>' || c == '/' || c == '='; };
        while (i < t.size() && !stop(t[i])) ++i;  // the element's name
        for (;;) {
            while (i < t.size() && is_space(t[i])) ++i;
            if (i >= t.size() || t[i] == '>' || t[i] == '/') break;
            const std::size_t name_at = i;
            std::size_t value_at = i;
            while (i < t.size() && !stop(t[i])) ++i;
            const std::string_view attribute = t.substr(name_at, i - name_at);
            while (i < t.size() && is_space(t[i])) ++i;
            if (i < t.size() && t[i] == '=') {
                ++i;
                while (i < t.size() && is_space(t[i])) ++i;
                if (i < t.size() && (t[i] == '"' || t[i] == '\'')) {
                    const char quote = t[i++];
                    value_at = i;
                    while (i < t.size() && t[i] != quote) ++i;
                    ++i;
                }
            }
            if (attribute == name) return {name_at, value_at};
            if (i == name_at) break;  // cannot happen in a document pugixml accepted
        }
        return {start, start};
    }

    [[noreturn]] void fail_at(pugi::xml_node n, const char* attribute,
                              const std::string& message) const {
        throw InputError(file_, attribute ? attribute_location(n, attribute) : element_location(n),
                         message);
    }

    // Runs parse(value of attribute) and gives its ValueError the attribute's place.
    template <class F>
    auto with_attribute(pugi::xml_node n, const char* attribute, F&& parse) const {
        try {
            return parse(std::string_view(n.attribute(attribute).value()));
        } catch (const svg::ValueError& e) {
            fail_at(n, attribute, e.what());
        }
    }

    // ---- names, styles -----------------------------------------------------------------------

    // The local name of an element in the SVG namespace ("" for others, e.g. sodipodi:namedview).
    // Unprefixed names count as SVG; a prefix counts when some ancestor binds it to SVG.
    static std::string svg_name(pugi::xml_node n) {
        const std::string name = n.name();
        const auto colon = name.find(':');
        if (colon == std::string::npos) return name;
        const std::string binding = "xmlns:" + name.substr(0, colon);
        for (pugi::xml_node a = n; a; a = a.parent()) {
            if (const pugi::xml_attribute ns = a.attribute(binding.c_str())) {
                return std::string(ns.value()) == kSvgNamespace ? name.substr(colon + 1) : "";
            }
        }
        return "";
    }

    // Reads every <style> element (SVG namespace, type text/css or none), wherever it is:
    // CSS applies to the whole document.
    void style_sheets(pugi::xml_node root) {
        std::vector<pugi::xml_node> todo{root};
        while (!todo.empty()) {
            const pugi::xml_node e = todo.back();
            todo.pop_back();
            if (svg_name(e) == "style") {
                const std::string type = lower(trim(e.attribute("type").value()));
                if (!type.empty() && type != "text/css") continue;
                for (pugi::xml_node c = e.first_child(); c; c = c.next_sibling()) {
                    if (c.type() != pugi::node_pcdata && c.type() != pugi::node_cdata) continue;
                    const std::ptrdiff_t at = c.offset_debug();
                    try {
                        sheet_.add(c.value(), at > 0 ? static_cast<std::size_t>(at) : 0);
                    } catch (const svg::CssError& error) {
                        throw InputError(file_, locate(error.offset), error.what());
                    }
                }
                continue;
            }
            for (pugi::xml_node c = e.last_child(); c; c = c.previous_sibling()) {
                if (c.type() == pugi::node_element) todo.push_back(c);
            }
        }
    }

    // The cascade for the properties the reader uses: presentation attribute < <style> rules
    // (by specificity, then order) < style attribute, and !important declarations above all
    // normal ones. Keywords are lower-cased; transform values keep their case.
    Style style(pugi::xml_node n) const {
        Style st;
        const auto attribute = [&](Cascaded& slot, const char* name) {
            if (const pugi::xml_attribute a = n.attribute(name)) {
                std::string v = trim(a.value());
                if (const auto bang = v.find("!important"); bang != std::string::npos)
                    v = trim(v.substr(0, bang));
                slot = {v, true, false, 0};
            }
        };
        attribute(st.display, "display");
        attribute(st.visibility, "visibility");
        attribute(st.stroke, "stroke");
        attribute(st.transform, "transform");
        attribute(st.origin, "transform-origin");
        attribute(st.clip_path, "clip-path");
        attribute(st.clip_rule, "clip-rule");
        attribute(st.overflow, "overflow");
        attribute(st.mask, "mask");
        attribute(st.filter, "filter");
        attribute(st.marker_start, "marker-start");
        attribute(st.marker_mid, "marker-mid");
        attribute(st.marker_end, "marker-end");
        attribute(st.fill, "fill");
        std::vector<const svg::CssDeclaration*> sheet;
        if (!sheet_.empty()) {
            sheet =
                sheet_.match(svg_name(n), n.attribute("id").value(), n.attribute("class").value());
        }
        std::vector<svg::CssDeclaration> inline_style;
        if (const pugi::xml_attribute a = n.attribute("style")) {
            try {
                inline_style =
                    svg::parse_css_declarations(a.value(), attribute_offsets(n, "style").second);
            } catch (const svg::CssError& error) {
                throw InputError(file_, locate(error.offset), error.what());
            }
        }
        const auto apply = [&](const svg::CssDeclaration& d) {
            Cascaded* slot = d.name == "display"            ? &st.display
                             : d.name == "visibility"       ? &st.visibility
                             : d.name == "stroke"           ? &st.stroke
                             : d.name == "transform"        ? &st.transform
                             : d.name == "transform-origin" ? &st.origin
                             : d.name == "clip-path"        ? &st.clip_path
                             : d.name == "clip-rule"        ? &st.clip_rule
                             : d.name == "overflow"         ? &st.overflow
                             : d.name == "mask"             ? &st.mask
                             : d.name == "filter"           ? &st.filter
                             : d.name == "marker"           ? &st.marker
                             : d.name == "marker-start"     ? &st.marker_start
                             : d.name == "marker-mid"       ? &st.marker_mid
                             : d.name == "marker-end"       ? &st.marker_end
                             : d.name == "fill"             ? &st.fill
                                                            : nullptr;
            if (slot) *slot = {d.value, true, true, d.name_offset};
        };
        for (const bool important : {false, true}) {
            for (const svg::CssDeclaration* d : sheet) {
                if (d->important == important) apply(*d);
            }
            for (const svg::CssDeclaration& d : inline_style) {
                if (d.important == important) apply(d);
            }
        }
        for (Cascaded* keyword :
             {&st.display, &st.visibility, &st.stroke, &st.clip_rule, &st.overflow})
            keyword->value = lower(keyword->value);
        return st;
    }

    // Applies a computed visibility and stroke to the inherited state.
    static void inherit(const Style& st, State& state) {
        if (st.visibility.value == "hidden" || st.visibility.value == "collapse")
            state.visible = false;
        if (st.visibility.value == "visible") state.visible = true;
        if (st.stroke.set && st.stroke.value != "inherit" && !st.stroke.value.empty())
            state.stroke = st.stroke.value;
    }

    // ---- values -----------------------------------------------------------------------------

    // The element's transform (CSS property, else attribute) about its transform-origin, whose
    // percentages and keywords refer to the viewport `width` x `height` in user units.
    Affine transform(pugi::xml_node n, const Style& st, double width, double height) const {
        if (!st.transform.set) return {};
        const auto parse = [&](const Cascaded& c, const char* attribute, auto&& f) {
            if (!c.css)
                return with_attribute(n, attribute, [&](std::string_view) { return f(c.value); });
            try {
                return f(c.value);
            } catch (const svg::ValueError& e) {
                throw InputError(file_, locate(c.offset), e.what());
            }
        };
        const Affine m = parse(st.transform, "transform", [&](std::string_view v) {
            return svg::parse_transform(v, st.transform.css);
        });
        if (!st.origin.set) return m;
        const Point o = parse(st.origin, "transform-origin", [&](std::string_view v) {
            return svg::parse_transform_origin(v, width, height);
        });
        return Affine::translate(o.x, o.y) * m * Affine::translate(-o.x, -o.y);
    }

    // A length attribute in user units; `fallback` when absent.
    double length(pugi::xml_node n, const char* attribute, double percent_base,
                  double fallback) const {
        if (!n.attribute(attribute)) return fallback;
        return with_attribute(n, attribute, [&](std::string_view v) {
            return svg::parse_length(v, attribute, percent_base);
        });
    }

    // A size (width, r, ...) that must not be negative.
    double size(pugi::xml_node n, const char* attribute, double percent_base,
                double fallback) const {
        const double v = length(n, attribute, percent_base, fallback);
        if (v < 0) {
            fail_at(n, attribute,
                    "<" + svg_name(n) + "> " + attribute + " must not be negative (got " +
                        trim(n.attribute(attribute).value()) + ")");
        }
        return v;
    }

    // rx / ry of rect and ellipse: NaN for "auto" or absent.
    double radius(pugi::xml_node n, const char* attribute, double percent_base) const {
        if (trim(n.attribute(attribute).value()) == "auto") return kNoBase;
        return size(n, attribute, percent_base, kNoBase);
    }

    std::optional<std::array<double, 4>> view_box(pugi::xml_node n) const {
        if (!n.attribute("viewBox")) return std::nullopt;
        return with_attribute(n, "viewBox", [](std::string_view v) {
            const std::vector<double> numbers = svg::parse_number_list(v, "viewBox");
            if (numbers.size() != 4) {
                throw svg::ValueError(
                    "viewBox: expected 4 numbers (min-x min-y width height), got " +
                    std::to_string(numbers.size()));
            }
            if (!(numbers[2] > 0) || !(numbers[3] > 0)) {
                throw svg::ValueError("viewBox: width and height must be positive (got " +
                                      number_text(numbers[2]) + " x " + number_text(numbers[3]) +
                                      ")");
            }
            return std::array<double, 4>{numbers[0], numbers[1], numbers[2], numbers[3]};
        });
    }

    Affine viewbox_map(pugi::xml_node n, const std::array<double, 4>& box, double width,
                       double height) const {
        return with_attribute(n, "preserveAspectRatio", [&](std::string_view v) {
            return svg::viewbox_transform(box, width, height, v);
        });
    }

    // ---- the walk ---------------------------------------------------------------------------

    void root_svg(pugi::xml_node n) {
        if (!conditions_hold(n)) return;  // e.g. a drawing for another language: nothing
        State state;
        const Style st = style(n);
        inherit(st, state);
        if (st.display.value == "none") return;
        // Width and height in px; percentages mean "no size given" for the outermost <svg>.
        const auto given = [&](const char* attribute) {
            const std::string v = trim(n.attribute(attribute).value());
            return !v.empty() && v.back() != '%';
        };
        double width = given("width") ? size(n, "width", kNoBase, 0) : kNoBase;
        double height = given("height") ? size(n, "height", kNoBase, 0) : kNoBase;
        Affine view;
        if (const auto box = view_box(n)) {
            const double w = (*box)[2], h = (*box)[3];
            if (std::isnan(width) && std::isnan(height)) {
                width = w;  // no size: one user unit is one px
                height = h;
            } else if (std::isnan(width)) {
                width = height * w / h;
            } else if (std::isnan(height)) {
                height = width * h / w;
            }
            view = viewbox_map(n, *box, width, height);
            state.width = w;
            state.height = h;
        } else {
            state.width = width;
            state.height = height;
        }
        if (width == 0 || height == 0) return;  // a zero-sized drawing draws nothing
        state.to_mm = Affine::scale(kMmPerPx, kMmPerPx) * transform(n, st, width, height) * view;
        if (state.to_mm.determinant() == 0) return;
        children(n, state);
    }

    void children(pugi::xml_node n, const State& state) {
        for (pugi::xml_node child = n.first_child(); child; child = child.next_sibling()) {
            if (child.type() == pugi::node_element) element(child, state);
        }
    }

    // SVG's conditional processing, on every element (not only in <switch>): the reader
    // supports no extensions, and its one language is kReaderLanguage, which matches a
    // systemLanguage entry equal to it or starting with it and '-' ("en", "en-US").
    static bool conditions_hold(pugi::xml_node n) {
        if (n.attribute("requiredExtensions")) return false;
        const pugi::xml_attribute languages = n.attribute("systemLanguage");
        if (!languages) return true;
        const std::string_view want = kReaderLanguage;
        const std::string list = languages.value();
        for (std::size_t i = 0; i <= list.size();) {
            std::size_t end = list.find(',', i);
            if (end == std::string::npos) end = list.size();
            const std::string tag = lower(trim(std::string_view(list).substr(i, end - i)));
            if (tag == want || (tag.size() > want.size() &&
                                tag.compare(0, want.size(), want) == 0 && tag[want.size()] == '-'))
                return true;
            i = end + 1;
        }
        return false;
    }

    // Counts one level of nesting for the walk below it.
    struct DepthGuard {
        std::size_t& depth;
        ~DepthGuard() { --depth; }
    };

    void element(pugi::xml_node n, const State& parent) {
        if (depth_ >= kMaxDepth) {
            fail_at(n, nullptr,
                    "elements nested more than " + std::to_string(kMaxDepth) +
                        " deep (the reader's limit)");
        }
        ++depth_;
        const DepthGuard guard{depth_};
        const std::string name = svg_name(n);
        if (name.empty() || !conditions_hold(n)) return;
        const Style st = style(n);
        if (st.display.value == "none") return;
        State state = parent;
        inherit(st, state);
        static const char* const kDrawn[] = {"g",       "a",    "switch",   "svg",
                                             "use",     "path", "rect",     "circle",
                                             "ellipse", "line", "polyline", "polygon"};
        if (std::find(std::begin(kDrawn), std::end(kDrawn), name) == std::end(kDrawn))
            return not_drawn(n, name);
        unapplied(n, st);
        const Affine own = transform(n, st, parent.width, parent.height);
        const std::size_t start = path_.subpaths.size();
        draw(n, name, parent, own, state);
        if (st.clip_path.set && st.clip_path.value != "none")
            clip_path(n, st, parent.to_mm * own, parent, start);
    }

    void draw(pugi::xml_node n, const std::string& name, const State& parent, const Affine& own,
              State& state) {
        if (name == "g") enter_layer(n, state);
        if (name == "g" || name == "a" || name == "switch") {
            state.to_mm = parent.to_mm * own;
            if (state.to_mm.determinant() == 0) return;
            if (name != "switch") return children(n, state);
            for (pugi::xml_node child = n.first_child(); child; child = child.next_sibling()) {
                if (child.type() == pugi::node_element && !svg_name(child).empty() &&
                    conditions_hold(child)) {
                    return element(child, state);
                }
            }
            return;
        }
        if (name == "svg") return nested_svg(n, parent, own, state);
        if (name == "use") return use(n, parent, own, state);
        state.to_mm = parent.to_mm * own;
        if (state.to_mm.determinant() == 0 || !state.visible) return;
        geometry(n, name, state);
    }

    void nested_svg(pugi::xml_node n, const State& parent, const Affine& own, State state) {
        const double x = length(n, "x", parent.width, 0), y = length(n, "y", parent.height, 0);
        const double width = size(n, "width", parent.width, parent.width);
        const double height = size(n, "height", parent.height, parent.height);
        viewport(n, parent.to_mm * own * Affine::translate(x, y), width, height, state);
    }

    // Enters the viewport of a nested <svg> or of a <symbol> drawn by <use>: `n`'s viewBox and
    // preserveAspectRatio map its user units onto width x height at the origin of `to_mm`.
    void viewport(pugi::xml_node n, const Affine& to_mm, double width, double height, State state) {
        if (width == 0 || height == 0) return;  // a zero-sized viewport draws nothing
        state.width = width;
        state.height = height;
        state.to_mm = to_mm;
        if (const auto box = view_box(n)) {
            if (std::isnan(width) || std::isnan(height)) {
                fail_at(n, "viewBox",
                        "a viewBox needs a viewport size (give <" + svg_name(n) +
                            "> a width and height, or the root <svg> a size)");
            }
            state.to_mm = to_mm * viewbox_map(n, *box, width, height);
            state.width = (*box)[2];
            state.height = (*box)[3];
        }
        if (state.to_mm.determinant() == 0) return;
        const std::size_t start = path_.subpaths.size();
        children(n, state);
        // overflow: hidden is the default of <svg> and <symbol>: what is outside is cut.
        const std::string overflow = style(n).overflow.value;
        if (overflow == "visible" || overflow == "auto" || path_.subpaths.size() == start) return;
        if (!std::isfinite(width) || !std::isfinite(height)) return;
        svg::Ring rect{to_mm({0, 0}), to_mm({width, 0}), to_mm({width, height}),
                       to_mm({0, height})};
        std::vector<svg::ClipShape> shapes(1);
        shapes[0].rings.push_back(std::move(rect));
        clip_subpaths(start, {std::make_shared<const svg::ClipRegion>(std::move(shapes))},
                      element_location(n));
    }

    // <use href="#id">: the element with that id, drawn here, moved by x and y. A <symbol>
    // gets a viewport of the use's width and height. Other files' content is not drawn.
    void use(pugi::xml_node n, const State& parent, const Affine& own, State state) {
        const char* const href_name = n.attribute("href") ? "href" : "xlink:href";
        const std::string href = trim(n.attribute(href_name).value());
        if (href.size() < 2 || href[0] != '#') return;
        // Every copy counts, of nothing too: a reference to nothing costs a lookup.
        if (++use_count_ > kMaxUses) {
            fail_at(n, nullptr,
                    "too many <use> copies (more than " + std::to_string(kMaxUses) + ")");
        }
        const pugi::xml_node target = element_by_id(href.substr(1));
        if (!target) return;  // SVG: a reference to nothing draws nothing
        for (const pugi::xml_node& active : use_stack_) {
            if (active == target) {
                fail_at(
                    n, href_name,
                    "<use> refers to " + href + ", which contains this <use> (circular reference)");
            }
        }
        const double x = length(n, "x", parent.width, 0), y = length(n, "y", parent.height, 0);
        const Affine to_mm = parent.to_mm * own * Affine::translate(x, y);
        if (to_mm.determinant() == 0) return;
        use_stack_.push_back(target);
        if (svg_name(target) == "symbol") {
            const Style target_style = style(target);
            if (target_style.display.value != "none") {
                inherit(target_style, state);
                const auto side = [&](const char* attribute, double base) {
                    if (n.attribute(attribute)) return size(n, attribute, base, base);
                    return size(target, attribute, base, base);
                };
                viewport(target,
                         to_mm * transform(target, target_style, parent.width, parent.height),
                         side("width", parent.width), side("height", parent.height), state);
            }
        } else {
            state.to_mm = to_mm;
            element(target, state);
        }
        use_stack_.pop_back();
    }

    pugi::xml_node element_by_id(const std::string& id) {
        if (!ids_built_) {
            ids_built_ = true;
            std::vector<pugi::xml_node> todo{doc_.document_element()};
            while (!todo.empty()) {
                const pugi::xml_node e = todo.back();
                todo.pop_back();
                if (const pugi::xml_attribute a = e.attribute("id"))
                    ids_.emplace(a.value(), e);  // first one wins
                for (pugi::xml_node c = e.last_child(); c; c = c.previous_sibling()) {
                    if (c.type() == pugi::node_element) todo.push_back(c);
                }
            }
        }
        const auto it = ids_.find(id);
        return it == ids_.end() ? pugi::xml_node() : it->second;
    }

    // ---- what is not drawn --------------------------------------------------------------

    // An SVG element that is not geometry: silent when it is not meant to be drawn where it
    // stands (definitions, metadata), a warning when it draws something the reader cannot.
    void not_drawn(pugi::xml_node n, const std::string& name) {
        static const char* const kSilent[] = {
            "defs",           "title",     "desc",          "metadata",
            "style",          "script",    "symbol",        "clipPath",
            "mask",           "marker",    "pattern",       "linearGradient",
            "radialGradient", "stop",      "filter",        "view",
            "cursor",         "animate",   "animateMotion", "animateTransform",
            "animateColor",   "set",       "mpath",         "discard",
            "font",           "font-face", "glyph",         "missing-glyph",
            "hkern",          "vkern",     "color-profile", "solidcolor",
            "meshgradient",   "hatch"};
        if (std::find(std::begin(kSilent), std::end(kSilent), name) != std::end(kSilent)) return;
        static const char* const kText[] = {"text",     "tspan",    "textPath", "tref",
                                            "flowRoot", "flowPara", "flowSpan", "flowRegion"};
        const bool text = std::find(std::begin(kText), std::end(kText), name) != std::end(kText);
        if (clip_building_ > 0) {
            if (clip_problem_.empty())
                clip_problem_ = "holds a <" + name + ">, which the reader cannot clip to";
            return;
        }
        const bool known = text || name == "image" || name == "foreignObject" || name == "video" ||
                           name == "audio" || name == "canvas" || name == "iframe" ||
                           name == "mesh";
        warnings_.add("<" + name + "> is not drawn" +
                          (text    ? " (convert text to paths to plot it)"
                           : known ? ""
                                   : " (an element the reader does not know)"),
                      element_location(n));
    }

    // Where a cascaded property was set: its attribute, or its CSS declaration.
    SourceLocation place(pugi::xml_node n, const Cascaded& c, const char* attribute) const {
        return c.css ? locate(c.offset) : attribute_location(n, attribute);
    }

    // Properties of a drawn element whose effect the reader does not draw.
    void unapplied(pugi::xml_node n, const Style& st) {
        if (clip_building_ > 0) return;
        const auto url = [](const Cascaded& c) { return c.set && c.value.rfind("url(", 0) == 0; };
        if (url(st.mask))
            warnings_.add("mask is not applied (drawn unmasked)", place(n, st.mask, "mask"));
        if (st.filter.set && st.filter.value != "none" && !st.filter.value.empty())
            warnings_.add("filter is not applied", place(n, st.filter, "filter"));
        const std::pair<const Cascaded*, const char*> markers[] = {
            {&st.marker, "marker"},
            {&st.marker_start, "marker-start"},
            {&st.marker_mid, "marker-mid"},
            {&st.marker_end, "marker-end"}};
        for (const auto& [c, attribute] : markers) {
            if (url(*c)) warnings_.add("markers are not drawn", place(n, *c, attribute));
        }
        for (const auto& [c, attribute] :
             {std::pair{&st.fill, "fill"}, std::pair{&st.stroke, "stroke"}}) {
            if (!url(*c)) continue;
            const pugi::xml_node paint = element_by_id(url_id(c->value));
            const std::string kind = paint ? svg_name(paint) : "";
            if (kind == "pattern" || kind == "hatch")
                warnings_.add("<" + kind + "> content is not drawn", place(n, *c, attribute));
        }
    }

    // The id of "url(#id)" (quotes allowed), or "" when the value is no such reference.
    static std::string url_id(const std::string& value) {
        if (value.rfind("url(", 0) != 0) return "";
        const std::size_t close = value.find(')');
        if (close == std::string::npos) return "";
        std::string inner = trim(std::string_view(value).substr(4, close - 4));
        if (inner.size() >= 2 && (inner[0] == '"' || inner[0] == '\'') && inner.back() == inner[0])
            inner = trim(std::string_view(inner).substr(1, inner.size() - 2));
        return inner.size() >= 2 && inner[0] == '#' ? inner.substr(1) : "";
    }

    // ---- clipping ---------------------------------------------------------------------------

    // Cuts what `n` drew (the subpaths from `start` on) by its clip-path, in the user space
    // `user_to_mm`; a clip that cannot be applied is a warning and the content stays whole.
    void clip_path(pugi::xml_node n, const Style& st, const Affine& user_to_mm, const State& parent,
                   std::size_t start) {
        if (clip_building_ > 0) {  // a clip of a clip's content: a union of intersections
            if (clip_problem_.empty()) clip_problem_ = "has content with its own clip-path";
            return;
        }
        if (path_.subpaths.size() == start) return;
        ClipRegions regions;
        const std::string problem =
            build_clip(st.clip_path.value, user_to_mm, parent, start, regions);
        const SourceLocation at = place(n, st.clip_path, "clip-path");
        if (!problem.empty()) return warnings_.add(problem + "; drawn unclipped", at);
        clip_subpaths(start, regions, at);
    }

    // The regions (a point must be in every one) of the clip-path value `value`, or why they
    // cannot be made.
    std::string build_clip(const std::string& value, const Affine& user_to_mm, const State& parent,
                           std::size_t start, ClipRegions& regions) {
        const std::string id = url_id(value);
        if (id.empty()) return "clip-path '" + value + "' is not a url(#id) (not supported)";
        const pugi::xml_node clip = element_by_id(id);
        if (!clip) return "clip-path refers to #" + id + ", which does not exist";
        if (svg_name(clip) != "clipPath")
            return "clip-path refers to #" + id + ", a <" + svg_name(clip) + ">, not a <clipPath>";
        if (std::find(clip_stack_.begin(), clip_stack_.end(), clip) != clip_stack_.end())
            return "clip-path #" + id + " refers to itself (circular reference)";
        if (clip_stack_.size() >= kMaxClipChain)
            return "clip paths clipped more than " + std::to_string(kMaxClipChain) + " deep";
        const Style clip_style = style(clip);
        Affine map = user_to_mm;
        if (trim(clip.attribute("clipPathUnits").value()) == "objectBoundingBox") {
            const auto box = user_box(start, user_to_mm);
            if (!box || (*box)[2] <= 0 || (*box)[3] <= 0) {
                regions.push_back(
                    std::make_shared<const svg::ClipRegion>(std::vector<svg::ClipShape>{}));
                warnings_.add(
                    "clip-path in objectBoundingBox units on content without an area "
                    "hides it",
                    element_location(clip));
                return "";
            }
            map = map * Affine{(*box)[2], 0, 0, (*box)[3], (*box)[0], (*box)[1]};
        }
        map = map * transform(clip, clip_style, parent.width, parent.height);
        if (map.determinant() == 0) {  // a collapsed clip has no inside
            regions.push_back(
                std::make_shared<const svg::ClipRegion>(std::vector<svg::ClipShape>{}));
            return "";
        }
        State inside = parent;
        inside.to_mm = map;
        inside.visible = true;
        inherit(clip_style, inside);
        const svg::FillRule clip_rule = rule(clip_style.clip_rule, svg::FillRule::kNonZero);
        std::vector<svg::ClipShape> shapes;
        clip_stack_.push_back(clip);
        ++clip_building_;
        for (pugi::xml_node child = clip.first_child(); child; child = child.next_sibling()) {
            if (child.type() != pugi::node_element) continue;
            const std::size_t from = path_.subpaths.size();
            element(child, inside);
            if (!clip_problem_.empty()) break;
            svg::ClipShape shape;
            shape.rule = rule(style(child).clip_rule, clip_rule);
            for (std::size_t i = from; i < path_.subpaths.size(); ++i)
                shape.rings.push_back(ring(path_.subpaths[i]));
            truncate(from);
            if (!shape.rings.empty()) shapes.push_back(std::move(shape));
        }
        --clip_building_;
        std::string problem;
        if (!clip_problem_.empty()) {
            problem = "clip-path #" + id + " " + clip_problem_;
            clip_problem_.clear();
        }
        if (problem.empty()) {
            regions.push_back(std::make_shared<const svg::ClipRegion>(std::move(shapes)));
            if (clip_style.clip_path.set && clip_style.clip_path.value != "none")
                problem =
                    build_clip(clip_style.clip_path.value, user_to_mm, parent, start, regions);
        }
        clip_stack_.pop_back();
        return problem;
    }

    static svg::FillRule rule(const Cascaded& c, svg::FillRule inherited) {
        if (c.value == "evenodd") return svg::FillRule::kEvenOdd;
        if (c.value == "nonzero") return svg::FillRule::kNonZero;
        return inherited;
    }

    // Drops the subpaths from `from` on (and what runs parallel to them).
    void truncate(std::size_t from) {
        path_.subpaths.resize(from);
        strokes_.resize(from);
        subpath_layers_.resize(from);
    }

    // A subpath's pieces in mm: a polyline's as straight cubics.
    static std::vector<svg::Cubic> pieces_of(const Subpath& s) {
        std::vector<svg::Cubic> out;
        const auto at = [&](std::size_t i) { return Point{s.points[i][0], s.points[i][1]}; };
        if (s.basis == PathBasis::kPolyline) {
            for (std::size_t i = 0; i + 1 < s.points.size(); ++i)
                out.push_back(svg::line_cubic(at(i), at(i + 1)));
        } else {
            for (std::size_t i = 0; i + 3 < s.points.size(); i += 3)
                out.push_back({at(i), at(i + 1), at(i + 2), at(i + 3)});
        }
        return out;
    }

    // A clip shape's subpath flattened within the tolerance (closed implicitly, as a fill is).
    svg::Ring ring(const Subpath& s) {
        svg::Ring out;
        for (const svg::Cubic& c : pieces_of(s)) {
            if (out.empty()) out.push_back(c[0]);
            const std::size_t n = svg::flatten_count(c, tolerance_mm_);
            charge_clip_work(n, s.location);
            for (std::size_t k = 1; k <= n; ++k) {
                const double t = static_cast<double>(k) / static_cast<double>(n), u = 1 - t;
                out.push_back(k == n ? c[3]
                                     : Point{u * u * u * c[0].x + 3 * u * u * t * c[1].x +
                                                 3 * u * t * t * c[2].x + t * t * t * c[3].x,
                                             u * u * u * c[0].y + 3 * u * u * t * c[1].y +
                                                 3 * u * t * t * c[2].y + t * t * t * c[3].y});
            }
        }
        return out;
    }

    void charge_clip_work(std::uint64_t n, SourceLocation at) {
        clip_work_ += n;
        if (clip_work_ > clip_budget()) {
            throw InputError(file_, at,
                             "clipping needs more than " + std::to_string(clip_budget()) +
                                 " steps (the reader's limit for a file of " +
                                 std::to_string(text_.size()) + " bytes)");
        }
    }

    std::uint64_t clip_budget() const { return kClipWorkBase + kClipWorkPerByte * text_.size(); }

    // The bounding box {x, y, width, height} of the subpaths from `start` on in the user
    // space `user_to_mm` maps from (curves by their extremes); none when there are none.
    std::optional<std::array<double, 4>> user_box(std::size_t start,
                                                  const Affine& user_to_mm) const {
        const double det = user_to_mm.determinant();
        const Affine& m = user_to_mm;
        const Affine inverse{m.d / det,
                             -m.b / det,
                             -m.c / det,
                             m.a / det,
                             (m.c * m.f - m.d * m.e) / det,
                             (m.b * m.e - m.a * m.f) / det};
        double lo[2] = {std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity()};
        double hi[2] = {-lo[0], -lo[1]};
        const auto add = [&](double v, int axis) {
            lo[axis] = std::min(lo[axis], v);
            hi[axis] = std::max(hi[axis], v);
        };
        for (std::size_t i = start; i < path_.subpaths.size(); ++i) {
            for (const svg::Cubic& mm : pieces_of(path_.subpaths[i])) {
                svg::Cubic c;
                for (int k = 0; k < 4; ++k) c[k] = inverse(mm[k]);
                for (int axis = 0; axis < 2; ++axis) {
                    const auto v = [&](int k) { return axis == 0 ? c[k].x : c[k].y; };
                    const auto at = [&](double t) {
                        const double u = 1 - t;
                        return u * u * u * v(0) + 3 * u * u * t * v(1) + 3 * u * t * t * v(2) +
                               t * t * t * v(3);
                    };
                    add(v(0), axis);
                    add(v(3), axis);
                    // Extremes inside: the roots of the derivative a t^2 + b t + c.
                    const double a = -v(0) + 3 * v(1) - 3 * v(2) + v(3);
                    const double b = 2 * (v(0) - 2 * v(1) + v(2)), q = v(1) - v(0);
                    std::vector<double> roots;
                    if (std::fabs(a) < 1e-12) {
                        if (b != 0) roots.push_back(-q / b);
                    } else if (const double disc = b * b - 4 * a * q; disc >= 0) {
                        roots.push_back((-b + std::sqrt(disc)) / (2 * a));
                        roots.push_back((-b - std::sqrt(disc)) / (2 * a));
                    }
                    for (const double t : roots) {
                        if (t > 0 && t < 1) add(at(t), axis);
                    }
                }
            }
        }
        if (!(lo[0] <= hi[0])) return std::nullopt;
        return std::array<double, 4>{lo[0], lo[1], hi[0] - lo[0], hi[1] - lo[1]};
    }

    // Replaces the subpaths from `start` on by their parts inside every region.
    void clip_subpaths(std::size_t start, const ClipRegions& regions, SourceLocation at) {
        std::vector<Subpath> kept;
        std::vector<std::string> strokes;
        std::vector<std::size_t> layers;
        const std::uint64_t budget = clip_budget();
        for (std::size_t i = start; i < path_.subpaths.size(); ++i) {
            svg::CubicSubpaths chains{pieces_of(path_.subpaths[i])};
            for (const auto& region : regions) {
                svg::CubicSubpaths cut;
                for (const auto& chain : chains) {
                    try {
                        for (auto& part :
                             svg::clip_chain(chain, *region, tolerance_mm_, clip_work_, budget))
                            cut.push_back(std::move(part));
                    } catch (const svg::ValueError&) {
                        charge_clip_work(budget, at);  // names the limit at the clip
                    }
                }
                chains = std::move(cut);
            }
            for (const auto& chain : chains) {
                bool straight = true;
                for (const svg::Cubic& c : chain) straight = straight && svg::is_straight(c);
                Subpath sp = subpath_of(
                    chain.size(), [&](std::size_t k) { return chain[k]; }, straight,
                    path_.subpaths[i].location);
                if (sp.points.empty()) continue;
                kept.push_back(std::move(sp));
                strokes.push_back(strokes_[i]);
                layers.push_back(subpath_layers_[i]);
            }
        }
        truncate(start);
        for (std::size_t k = 0; k < kept.size(); ++k) {
            path_.subpaths.push_back(std::move(kept[k]));
            strokes_.push_back(std::move(strokes[k]));
            subpath_layers_.push_back(layers[k]);
        }
    }

    void geometry(pugi::xml_node n, const std::string& name, const State& state) {
        const double w = state.width, h = state.height;
        const double diagonal = std::sqrt((w * w + h * h) / 2);  // what 100% of r is
        const Affine& m = state.to_mm;
        if (name == "path") {
            if (!n.attribute("d")) return;
            const CubicSubpaths pieces = with_attribute(n, "d", [&](std::string_view d) {
                return svg::parse_path_data(d, m, tolerance_mm_);
            });
            return emit(pieces, state, attribute_location(n, "d"));
        }
        if (name == "polyline" || name == "polygon") {
            const std::vector<Point> points = with_attribute(n, "points", [](std::string_view v) {
                const std::vector<double> numbers = svg::parse_number_list(v, "points");
                if (numbers.size() % 2 != 0) {
                    throw svg::ValueError("points: odd number of coordinates (" +
                                          std::to_string(numbers.size()) + ")");
                }
                std::vector<Point> out;
                for (std::size_t i = 0; i < numbers.size(); i += 2)
                    out.push_back({numbers[i], numbers[i + 1]});
                return out;
            });
            return emit(CubicSubpaths{svg::polyline_cubics(points, name == "polygon")}, state,
                        attribute_location(n, "points"));
        }
        const SourceLocation at = element_location(n);
        if (name == "line") {
            const Point a{length(n, "x1", w, 0), length(n, "y1", h, 0)};
            const Point b{length(n, "x2", w, 0), length(n, "y2", h, 0)};
            return emit(CubicSubpaths{std::vector<svg::Cubic>{svg::line_cubic(a, b)}}, state, at);
        }
        if (name == "rect") {
            const double x = length(n, "x", w, 0), y = length(n, "y", h, 0);
            const double width = size(n, "width", w, 0), height = size(n, "height", h, 0);
            double rx = radius(n, "rx", w), ry = radius(n, "ry", h);
            if (width == 0 || height == 0) return;
            if (std::isnan(rx) && std::isnan(ry))
                rx = ry = 0;
            else if (std::isnan(rx))
                rx = ry;
            else if (std::isnan(ry))
                ry = rx;
            rx = std::min(rx, width / 2);
            ry = std::min(ry, height / 2);
            return emit(
                CubicSubpaths{svg::rect_cubics(x, y, width, height, rx, ry, m, tolerance_mm_)},
                state, at);
        }
        const Point center{length(n, "cx", w, 0), length(n, "cy", h, 0)};
        double rx = 0, ry = 0;
        if (name == "circle") {
            rx = ry = size(n, "r", diagonal, 0);
        } else {  // ellipse
            rx = radius(n, "rx", w);
            ry = radius(n, "ry", h);
            if (std::isnan(rx)) rx = std::isnan(ry) ? 0 : ry;
            if (std::isnan(ry)) ry = rx;
        }
        if (rx == 0 || ry == 0) return;
        emit(CubicSubpaths{svg::ellipse_cubics(center, rx, ry, m, tolerance_mm_)}, state, at);
    }

    // Maps pieces to mm and appends them as Bezier subpaths.
    void emit(const CubicSubpaths& subpaths, const State& state, SourceLocation at) {
        const Affine& to_mm = state.to_mm;
        const std::size_t budget = kPiecesBase + kPiecesPerByte * text_.size();
        for (const auto& pieces : subpaths) {
            pieces_ += pieces.size();
            if (pieces_ > budget) {
                throw InputError(file_, at,
                                 "the drawing expands to more than " + std::to_string(budget) +
                                     " curve pieces (the reader's limit for a file of " +
                                     std::to_string(text_.size()) + " bytes; <use> copies count)");
            }
            // Only straight pieces (lines, polylines, rectangles without corners): a polyline
            // of their ends, 1 point a piece instead of 3; the planner makes the same straight
            // cubics of it (docs/formats-svg.md).
            const bool straight =
                std::all_of(pieces.begin(), pieces.end(),
                            [](const svg::Cubic& c) { return c == svg::line_cubic(c[0], c[3]); });
            // Mapped one at a time: a copy of 10^6 pieces in mm would cost 64 MB.
            Subpath sp = subpath_of(
                pieces.size(),
                [&](std::size_t i) {
                    svg::Cubic mm;
                    for (int k = 0; k < 4; ++k) mm[k] = to_mm(pieces[i][k]);
                    return mm;
                },
                straight, at);
            if (sp.points.empty()) continue;
            path_.subpaths.push_back(std::move(sp));
            strokes_.push_back(state.stroke);
            subpath_layers_.push_back(state.layer);
        }
    }

    // A subpath of pieces in mm (a polyline of their ends when `straight`), without the pieces
    // smaller than kDegenerateMm; checked against the coordinate range.
    // piece(i) gives piece i of `count` in mm.
    template <class Piece>
    Subpath subpath_of(std::size_t count, Piece&& piece, bool straight, SourceLocation at) const {
        Subpath sp;
        sp.basis = straight ? PathBasis::kPolyline : PathBasis::kBezier;
        sp.closed = false;
        sp.location = at;
        // At most this many points: no growth by doubling.
        sp.points.reserve((straight ? 1 : 3) * count + 1, 2);
        for (std::size_t i = 0; i < count; ++i) {
            const svg::Cubic mm = piece(i);
            bool degenerate = true;
            for (int k = 0; k < 4; ++k) {
                degenerate =
                    degenerate && std::hypot(mm[k].x - mm[0].x, mm[k].y - mm[0].y) <= kDegenerateMm;
            }
            if (degenerate) continue;
            for (int k = sp.points.empty() ? 0 : 1; k < 4; ++k) {
                if (straight && (k == 1 || k == 2)) continue;  // a polyline keeps the ends
                check(mm[k].x, at);
                check(mm[k].y, at);
                sp.points.push_back({mm[k].x, mm[k].y});
            }
        }
        return sp;
    }

    void check(double mm, SourceLocation at) const {
        if (!std::isfinite(mm))
            throw InputError(file_, at, "coordinate is not finite after units and transforms");
        if (std::fabs(mm) > kMaxCoordinateMm) {
            throw InputError(file_, at,
                             "coordinate " + number_text(mm, 10) +
                                 " mm is out of range (|value| <= " +
                                 number_text(kMaxCoordinateMm) + " mm after units and transforms)");
        }
    }

    const std::string& text_;
    const std::string& file_;
    double tolerance_mm_;
    mutable svg::TextLocator locator_;  // lookups only count their cost
    pugi::xml_document doc_;
    Path path_;
    std::unordered_map<std::string, pugi::xml_node> ids_;
    bool ids_built_ = false;
    std::vector<pugi::xml_node> use_stack_;  // targets of the <use> elements being drawn
    std::size_t use_count_ = 0;
    std::size_t depth_ = 0;   // elements being walked, nested
    std::size_t pieces_ = 0;  // curve pieces emitted so far
    svg::StyleSheet sheet_;
    std::vector<std::string> strokes_;         // parallel to path_.subpaths
    std::vector<std::size_t> subpath_layers_;  // parallel to path_.subpaths: index in layers_
    std::vector<PathLayer> layers_;            // Inkscape layers in document order
    svg::WarningLog warnings_;
    std::vector<pugi::xml_node> clip_stack_;  // clipPath elements being built, for cycles
    std::size_t clip_building_ = 0;           // > 0 while a clipPath's content is walked
    std::string clip_problem_;                // why the clipPath being built cannot clip
    std::uint64_t clip_work_ = 0;             // clipping steps so far (clip_budget())
};

}  // namespace

Path parse_svg_path(const std::string& text, const std::string& file, double tolerance_mm,
                    svg::SvgReadInfo* info) {
    if (!(tolerance_mm > 0) || !std::isfinite(tolerance_mm)) {
        throw InputError(
            file, {},
            "tolerance must be positive and finite (got " + number_text(tolerance_mm) + " mm)");
    }
    return Reader(text, file, tolerance_mm).read(info);
}

Path load_svg_path(const std::string& file, double tolerance_mm) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return parse_svg_path(buffer.str(), file, tolerance_mm);
}

}  // namespace pathstream::host
