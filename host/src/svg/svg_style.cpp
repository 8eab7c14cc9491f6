// A small CSS subset for <style> elements and style attributes (docs/formats-svg.md): enough for
// the class rules editors write (Illustrator hides layers with .st2{display:none}).
#include <algorithm>
#include <iterator>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {
namespace {

// The properties the reader uses; declarations of others are dropped when a sheet is read.
// Beyond what decides the geometry: clipping, and what the reader warns it does not draw.
constexpr std::string_view kUsed[] = {
    "display",   "visibility",   "stroke",     "transform",  "transform-origin",
    "clip-path", "clip-rule",    "overflow",   "mask",       "filter",
    "marker",    "marker-start", "marker-mid", "marker-end", "fill"};
static_assert(std::size(kUsed) == StyleSheet::kProperties);

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f';
}

// CSS identifier characters (escapes are not supported: such selectors never match).
bool is_ident(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
           c == '_' || static_cast<unsigned char>(c) >= 0x80;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

// `text` with every comment blanked to spaces, so offsets stay; throws on an unclosed one.
std::string blank_comments(std::string_view text, std::size_t base) {
    std::string out(text);
    char quote = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
        if (quote) {
            if (out[i] == '\\')
                ++i;
            else if (out[i] == quote)
                quote = 0;
        } else if (out[i] == '"' || out[i] == '\'') {
            quote = out[i];
        } else if (out[i] == '/' && i + 1 < out.size() && out[i + 1] == '*') {
            const std::size_t end = out.find("*/", i + 2);
            if (end == std::string::npos) throw CssError("style: unclosed comment '/*'", base + i);
            std::fill(out.begin() + static_cast<std::ptrdiff_t>(i),
                      out.begin() + static_cast<std::ptrdiff_t>(end + 2), ' ');
            i = end + 1;
        }
    }
    return out;
}

// Offset of the first of `stops` at or after `i` outside strings and parentheses, or npos.
std::size_t find_outside(std::string_view t, std::size_t i, std::string_view stops) {
    char quote = 0;
    int depth = 0;
    for (; i < t.size(); ++i) {
        const char c = t[i];
        if (quote) {
            if (c == '\\')
                ++i;
            else if (c == quote)
                quote = 0;
        } else if (c == '"' || c == '\'') {
            quote = c;
        } else if (c == '(') {
            ++depth;
        } else if (c == ')' && depth > 0) {
            --depth;
        } else if (depth == 0 && stops.find(c) != std::string_view::npos) {
            return i;
        }
    }
    return std::string_view::npos;
}

// Offset just after the '}' that closes the block opened at `open`, or npos.
std::size_t block_end(std::string_view t, std::size_t open) {
    int depth = 0;
    for (std::size_t i = open; i < t.size();) {
        const std::size_t at = find_outside(t, i, "{}");
        if (at == std::string_view::npos) return at;
        depth += t[at] == '{' ? 1 : -1;
        if (depth == 0) return at + 1;
        i = at + 1;
    }
    return std::string_view::npos;
}

}  // namespace

std::vector<CssDeclaration> parse_css_declarations(std::string_view text, std::size_t base) {
    const std::string t = blank_comments(text, base);
    std::vector<CssDeclaration> out;
    for (std::size_t i = 0; i <= t.size();) {
        std::size_t end = find_outside(t, i, ";");
        if (end == std::string_view::npos) end = t.size();
        const std::string_view declaration = std::string_view(t).substr(i, end - i);
        const std::size_t colon = declaration.find(':');
        const std::string_view name = trim(declaration.substr(0, colon));
        if (colon != std::string_view::npos && !name.empty()) {
            CssDeclaration d;
            for (const char c : name)
                d.name += (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
            std::string_view value = declaration.substr(colon + 1);
            while (!value.empty() && is_space(value.front())) value.remove_prefix(1);
            d.value_offset = base + i + static_cast<std::size_t>(value.data() - declaration.data());
            d.name_offset = base + i + static_cast<std::size_t>(name.data() - declaration.data());
            value = trim(value);
            if (const std::size_t bang = value.rfind('!'); bang != std::string_view::npos) {
                std::string flag;
                for (const char c : trim(value.substr(bang + 1)))
                    flag += (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
                if (flag == "important") {
                    d.important = true;
                    value = trim(value.substr(0, bang));
                }
            }
            d.value = std::string(value);
            out.push_back(std::move(d));
        }
        i = end + 1;
    }
    return out;
}

void StyleSheet::add(std::string_view css, std::size_t base) {
    const std::string t = blank_comments(css, base);
    const std::string_view v = t;
    std::size_t i = 0;
    for (;;) {
        // CDO and CDC ("<!--", "-->") are allowed between rules and mean nothing.
        while (i < v.size() && is_space(v[i])) ++i;
        if (v.substr(i, 4) == "<!--") {
            i += 4;
            continue;
        }
        if (v.substr(i, 3) == "-->") {
            i += 3;
            continue;
        }
        if (i >= v.size()) return;
        const std::size_t start = i;
        const std::size_t stop = find_outside(v, i, v[i] == '@' ? "{};" : "{}");
        if (stop == std::string_view::npos) {
            if (v[i] == '@') return;  // an unterminated at-rule at the end: nothing to skip
            throw CssError("style: expected '{' after the selector '" +
                               std::string(trim(v.substr(start, 40))) + "'",
                           base + start);
        }
        if (v[stop] == '}') throw CssError("style: unexpected '}'", base + stop);
        if (v[stop] == ';') {  // @import, @charset, @namespace
            i = stop + 1;
            continue;
        }
        const std::size_t end = block_end(v, stop);
        if (end == std::string_view::npos)
            throw CssError("style: unclosed '{' (no matching '}')", base + stop);
        if (v[start] != '@') {  // at-rules (@media, @font-face, ...) are skipped whole
            std::vector<CssDeclaration> all =
                parse_css_declarations(v.substr(stop + 1, end - stop - 2), base + stop + 1);
            std::vector<CssDeclaration> used;
            for (CssDeclaration& d : all) {
                if (std::find(std::begin(kUsed), std::end(kUsed), d.name) != std::end(kUsed))
                    used.push_back(std::move(d));
            }
            const std::size_t block = blocks_.size();
            blocks_.push_back(std::move(used));
            const std::string_view prelude = v.substr(start, stop - start);
            for (std::size_t k = 0; k <= prelude.size();) {
                std::size_t comma = find_outside(prelude, k, ",");
                if (comma == std::string_view::npos) comma = prelude.size();
                if (++count_ > kMaxRules) {
                    throw CssError("style: more than " + std::to_string(kMaxRules) +
                                       " rules (each selector of a list counts)",
                                   base + start);
                }
                if (!blocks_[block].empty()) add_rule(trim(prelude.substr(k, comma - k)), block);
                k = comma + 1;
            }
        }
        i = end;
    }
}

void StyleSheet::add_rule(std::string_view selector, std::size_t block) {
    Rule r;
    std::size_t i = 0;
    if (i < selector.size() && selector[i] == '*') {
        ++i;
    } else {
        while (i < selector.size() && is_ident(selector[i])) r.type += selector[i++];
    }
    std::uint32_t ids = 0, classes = 0;
    while (i < selector.size()) {
        const char kind = selector[i++];
        std::string name;
        while (i < selector.size() && is_ident(selector[i])) name += selector[i++];
        if (name.empty() || (kind != '.' && kind != '#')) return;  // unsupported: never matches
        if (kind == '#') {
            if (!r.id.empty() && r.id != name) return;  // two ids: matches nothing
            r.id = name;
            ++ids;
        } else {
            r.classes.push_back(name);
            ++classes;
        }
    }
    if (i == 0) return;  // empty selector
    r.specificity = std::min<std::uint32_t>(ids, 1023) << 20 |
                    std::min<std::uint32_t>(classes, 1023) << 10 | (r.type.empty() ? 0 : 1);
    std::vector<std::string> sorted = r.classes;
    std::sort(sorted.begin(), sorted.end());
    std::string key = std::to_string(r.specificity) + " " + r.type + "#" + r.id;
    for (const std::string& c : sorted) key += "." + c;
    auto [it, fresh] = by_selector_.emplace(key, rules_.size());
    if (fresh) {
        const std::size_t index = rules_.size();
        if (!r.id.empty())
            by_id_[r.id].push_back(index);
        else if (!r.classes.empty())
            by_class_[r.classes.front()].push_back(index);
        else
            by_type_[r.type.empty() ? "*" : r.type].push_back(index);
        rules_.push_back(std::move(r));
    }
    Rule& rule = rules_[it->second];
    for (const CssDeclaration& d : blocks_[block]) {
        const auto p = static_cast<std::size_t>(
            std::find(std::begin(kUsed), std::end(kUsed), d.name) - std::begin(kUsed));
        rule.slots[p][d.important ? 1 : 0] = {&d, ++declarations_};
    }
}

std::vector<const CssDeclaration*> StyleSheet::match(std::string_view type, std::string_view id,
                                                     std::string_view classes) const {
    std::vector<std::string> own;  // the element's classes, sorted, each once
    for (std::size_t i = 0; i < classes.size();) {
        while (i < classes.size() && is_space(classes[i])) ++i;
        const std::size_t start = i;
        while (i < classes.size() && !is_space(classes[i])) ++i;
        if (i > start) own.emplace_back(classes.substr(start, i - start));
    }
    std::sort(own.begin(), own.end());
    own.erase(std::unique(own.begin(), own.end()), own.end());

    std::vector<std::size_t> candidates;
    const auto gather = [&](const auto& index, const std::string& key) {
        if (const auto it = index.find(key); it != index.end())
            candidates.insert(candidates.end(), it->second.begin(), it->second.end());
    };
    if (!id.empty()) gather(by_id_, std::string(id));
    for (const std::string& c : own) gather(by_class_, c);
    gather(by_type_, std::string(type));
    gather(by_type_, "*");

    std::array<std::array<Slot, 2>, kProperties> best{};
    std::array<std::array<std::uint32_t, 2>, kProperties> best_specificity{};
    for (const std::size_t k : candidates) {
        const Rule& r = rules_[k];
        bool ok = (r.type.empty() || r.type == type) && (r.id.empty() || r.id == id);
        for (const std::string& c : r.classes)
            ok = ok && std::binary_search(own.begin(), own.end(), c);
        if (!ok) continue;
        for (std::size_t p = 0; p < best.size(); ++p) {
            for (std::size_t imp = 0; imp < 2; ++imp) {
                const Slot& s = r.slots[p][imp];
                if (!s.declaration) continue;
                Slot& b = best[p][imp];
                std::uint32_t& bs = best_specificity[p][imp];
                if (!b.declaration || r.specificity > bs ||
                    (r.specificity == bs && s.order > b.order)) {
                    b = s;
                    bs = r.specificity;
                }
            }
        }
    }
    std::vector<const CssDeclaration*> out;
    for (const auto& slot : best) {
        for (const Slot& s : slot) {
            if (s.declaration) out.push_back(s.declaration);
        }
    }
    return out;
}

}  // namespace pathstream::host::svg
