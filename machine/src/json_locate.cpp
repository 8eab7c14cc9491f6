#include "pathstream/machine/json_locate.hpp"

#include <algorithm>
#include <cstring>
#include <nlohmann/json.hpp>
#include <unordered_set>

namespace pathstream::host {

namespace {
thread_local std::size_t bytes_scanned = 0;

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}
}  // namespace

std::size_t json_bytes_scanned() {
    return bytes_scanned;
}

// One forgiving pass over text nlohmann::json has accepted: it only needs where each value
// starts, so it skips strings and scalars without validating them. Iterative, so a deeply
// nested document cannot exhaust the stack.
class JsonIndexBuilder {
public:
    JsonIndexBuilder(std::string_view text, JsonIndex& index, std::size_t max_depth)
        : text_(text), index_(index), max_depth_(max_depth) {}

    void build() {
        index_lines();
        skip_space();
        scan_values();
        skip_space();
        if (pos_ < text_.size()) index_.trailing_byte_ = pos_;
        bytes_scanned += std::min(pos_, text_.size());
    }

private:
    struct Open {
        std::size_t node;
        bool object;
        std::unordered_set<std::string> keys;
    };

    void index_lines() {  // memchr: the one full pass besides the scan itself
        index_.line_starts_.push_back(0);
        const char* const begin = text_.data();
        const char* const end = begin + text_.size();
        for (const char* p = begin; p < end;) {
            const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
            if (!nl) break;
            p = static_cast<const char*>(nl) + 1;
            index_.line_starts_.push_back(static_cast<std::size_t>(p - begin));
        }
        bytes_scanned += text_.size();
    }

    bool at(char c) const { return pos_ < text_.size() && text_[pos_] == c; }

    void skip_space() {
        while (pos_ < text_.size() && is_space(text_[pos_])) ++pos_;
    }

    void skip_string() {  // at '"'
        ++pos_;
        while (pos_ < text_.size() && text_[pos_] != '"') pos_ += text_[pos_] == '\\' ? 2 : 1;
        ++pos_;
    }

    std::string key() {  // at '"'; decoded, so "\u0061" and "a" are the same key
        const std::size_t start = pos_;
        skip_string();
        const std::string_view raw = text_.substr(start, std::min(pos_, text_.size()) - start);
        if (raw.size() < 2) return std::string(raw);
        if (raw.find('\\') == std::string_view::npos)
            return std::string(raw.substr(1, raw.size() - 2));
        const auto decoded = nlohmann::json::parse(raw, nullptr, false);
        return decoded.is_string() ? decoded.get<std::string>() : std::string(raw);
    }

    // Records a value starting at pos_ as the next child of the innermost open container
    // (kNone: nested too deep to be recorded).
    std::size_t add_node() {
        if (open_.size() > max_depth_) return kNone;
        const std::size_t id = index_.nodes_.size();
        index_.nodes_.push_back({pos_, false, {}, {}});
        if (!open_.empty()) index_.nodes_[open_.back().node].children.push_back(id);
        return id;
    }

    // After an object's '{' or ',': reads `"key":` and leaves pos_ at the member's value.
    bool member_key() {
        if (!at('"')) return false;
        const std::size_t key_at = pos_;
        std::string k = key();
        if (!open_.back().keys.insert(k).second && !index_.duplicate_key_) {
            index_.duplicate_key_ = key_at;
        }
        if (open_.back().node != kNone)
            index_.nodes_[open_.back().node].keys.push_back(std::move(k));
        skip_space();
        if (!at(':')) return false;
        ++pos_;
        skip_space();
        return true;
    }

    void scan_values() {
        while (pos_ < text_.size()) {
            const std::size_t id = add_node();
            const char c = text_[pos_];
            if (c == '{' || c == '[') {
                if (id != kNone) index_.nodes_[id].object = c == '{';
                open_.push_back({id, c == '{', {}});
                ++pos_;
                skip_space();
                if (!at(c == '{' ? '}' : ']')) {
                    if (c == '{' && !member_key()) return;
                    continue;
                }
            } else if (c == '"') {
                skip_string();
                continue_after_value();
                if (done_) return;
                continue;
            } else {
                while (pos_ < text_.size() && text_[pos_] != ',' && text_[pos_] != ']' &&
                       text_[pos_] != '}' && !is_space(text_[pos_])) {
                    ++pos_;
                }
                continue_after_value();
                if (done_) return;
                continue;
            }
            // An empty container: close it at once.
            ++pos_;
            open_.pop_back();
            continue_after_value();
            if (done_) return;
        }
    }

    // After a value: closes finished containers; stops at the next value (done_ if none).
    void continue_after_value() {
        for (;;) {
            skip_space();
            if (open_.empty() || pos_ >= text_.size()) {
                done_ = true;
                return;
            }
            if (text_[pos_] == ',') {
                ++pos_;
                skip_space();
                if (open_.back().object && !member_key()) done_ = true;
                return;
            }
            if (text_[pos_] == '}' || text_[pos_] == ']') {
                ++pos_;
                open_.pop_back();
                continue;
            }
            done_ = true;  // not JSON nlohmann would accept: stop indexing here
            return;
        }
    }

    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

    std::string_view text_;
    JsonIndex& index_;
    std::size_t max_depth_;
    std::size_t pos_ = 0;
    bool done_ = false;
    std::vector<Open> open_;
};

JsonIndex::JsonIndex(std::string_view text, std::size_t max_depth) {
    JsonIndexBuilder(text, *this, max_depth).build();
}

std::optional<std::size_t> JsonIndex::offset_of(const std::string& pointer) const {
    if (nodes_.empty()) return std::nullopt;
    std::size_t node = 0;
    std::size_t at = 0;
    while (at < pointer.size()) {
        if (pointer[at] != '/') return std::nullopt;
        const std::size_t end = std::min(pointer.find('/', at + 1), pointer.size());
        std::string token;
        for (std::size_t i = at + 1; i < end; ++i) {  // RFC 6901: ~1 -> /, ~0 -> ~
            if (pointer[i] == '~' && i + 1 < end &&
                (pointer[i + 1] == '0' || pointer[i + 1] == '1')) {
                token += pointer[++i] == '1' ? '/' : '~';
            } else {
                token += pointer[i];
            }
        }
        at = end;
        const Node& n = nodes_[node];
        if (n.object) {
            const auto key = std::find(n.keys.begin(), n.keys.end(), token);
            if (key == n.keys.end()) return std::nullopt;
            const auto i = static_cast<std::size_t>(key - n.keys.begin());
            if (i >= n.children.size()) return std::nullopt;
            node = n.children[i];
        } else {
            if (token.empty() || token.size() > 18 ||
                !std::all_of(token.begin(), token.end(),
                             [](char c) { return c >= '0' && c <= '9'; })) {
                return std::nullopt;
            }
            const std::size_t i = std::stoull(token);
            if (i >= n.children.size()) return std::nullopt;
            node = n.children[i];
        }
    }
    return nodes_[node].offset;
}

SourceLocation JsonIndex::location_of(std::size_t offset) const {
    const auto next = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    const auto line = static_cast<std::size_t>(next - line_starts_.begin());  // >= 1: starts has 0
    return {line, offset - line_starts_[line - 1] + 1};
}

SourceLocation JsonIndex::locate(const std::string& pointer) const {
    const auto offset = offset_of(pointer);
    return offset ? location_of(*offset) : SourceLocation{};
}

}  // namespace pathstream::host
