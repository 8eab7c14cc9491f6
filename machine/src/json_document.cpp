#include "pathstream/machine/json_document.hpp"

#include <algorithm>
#include <string_view>

#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {

namespace {

// What nlohmann::json accepts but a pathstream document must not contain: a key twice in
// one object (nlohmann keeps the last) and bytes after the value (it stops at a NUL byte).
void check_strict(const std::string& text, const std::string& file, const JsonIndex& index) {
    if (const auto at = index.duplicate_key()) {
        throw InputError(file, index.location_of(*at), "duplicate key in one object");
    }
    if (const auto at = index.trailing_byte()) {
        const std::string what = text[*at] == '\0' ? "a NUL byte" : "bytes";
        throw InputError(file, index.location_of(*at),
                         "invalid JSON: " + what + " after the document");
    }
}

// No pathstream document nests more than a few levels; the parser's cost and memory for a
// hostile one 8 million levels deep (16 MB of brackets) were 84 s and 1.9 GB before its error.
// One pass over the bytes refuses it at the first bracket past the limit.
constexpr std::size_t kMaxJsonDepth = 256;

void check_depth(const std::string& text, const std::string& file) {
    std::size_t depth = 0;
    bool in_string = false, escaped = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (in_string) {
            if (escaped) {
                escaped = false;
            } else if (c == '\\') {
                escaped = true;
            } else if (c == '"') {
                in_string = false;
            }
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth) {
                throw InputError(file, JsonIndex(text, 0).location_of(i),
                                 "invalid JSON: nested more than " + std::to_string(kMaxJsonDepth) +
                                     " levels deep (the reader's limit)");
            }
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
}

/// Builds the document as nlohmann::json::parse does (its own SAX DOM builder gets every
/// event), except the arrays `flat` names: those go into flat rows while they hold only rows of
/// numbers; anything else in them replays what was read into the builder, which goes on.
class FlatSax {
public:
    using json = nlohmann::json;

    FlatSax(json& root, FlatNumberArrays& flat) : dom_(root), flat_(flat) {
        for (const std::string& where : flat.where) {
            max_depth_ = std::max(
                max_depth_, static_cast<std::size_t>(std::count(where.begin(), where.end(), '/')));
        }
    }

    bool null() {
        return other_value([&] { return dom_.null(); });
    }
    bool boolean(bool v) {
        return other_value([&] { return dom_.boolean(v); });
    }
    bool number_integer(json::number_integer_t v) {
        return number(static_cast<double>(v), [&] { return dom_.number_integer(v); });
    }
    bool number_unsigned(json::number_unsigned_t v) {
        return number(static_cast<double>(v), [&] { return dom_.number_unsigned(v); });
    }
    bool number_float(json::number_float_t v, const json::string_t& s) {
        return number(v, [&] { return dom_.number_float(v, s); });
    }
    bool string(json::string_t& v) {
        return other_value([&] { return dom_.string(v); });
    }
    bool binary(json::binary_t& v) {
        return other_value([&] { return dom_.binary(v); });
    }

    bool start_object(std::size_t n) {
        if (capturing_) give_up();
        counted();
        frames_.push_back({true, {}, 0});
        return dom_.start_object(n);
    }
    bool key(json::string_t& k) {
        frames_.back().key = k;
        return dom_.key(k);
    }
    bool end_object() {
        frames_.pop_back();
        return dom_.end_object();
    }

    bool start_array(std::size_t n) {
        if (capturing_ && !in_row_) {
            in_row_ = true;
            row_width_ = 0;
            return true;
        }
        if (capturing_) give_up();
        counted();
        if (frames_.size() <= max_depth_ && !flat_.where.empty()) {
            std::string at = pointer();
            if (wanted(at)) {
                capturing_ = true;
                capture_at_ = std::move(at);
                rows_ = {};
                return true;
            }
        }
        frames_.push_back({false, {}, 0});
        return dom_.start_array(n);
    }
    bool end_array() {
        if (capturing_ && in_row_) {
            rows_.widths.push_back(static_cast<std::uint8_t>(row_width_));
            in_row_ = false;
            return true;
        }
        if (capturing_) {  // the flat array ends: an empty one stands in the document
            capturing_ = false;
            flat_.found[capture_at_] = std::move(rows_);
            rows_ = {};
            return dom_.start_array(kUnknownSize) && dom_.end_array();
        }
        frames_.pop_back();
        return dom_.end_array();
    }

    template <class Exception>
    bool parse_error(std::size_t position, const std::string& token, const Exception& e) {
        return dom_.parse_error(position, token, e);  // throws e
    }

private:
    static constexpr std::size_t kUnknownSize = static_cast<std::size_t>(-1);

    struct Frame {
        bool object;
        std::string key;        ///< objects: the current member's
        std::size_t count = 0;  ///< arrays: elements begun so far
    };

    template <class Add>
    bool other_value(Add add) {
        if (capturing_) give_up();
        counted();
        return add();
    }

    template <class Add>
    bool number(double v, Add add) {
        if (capturing_ && in_row_ && row_width_ < 255) {
            rows_.values.push_back(v);
            ++row_width_;
            return true;
        }
        return other_value(add);
    }

    void counted() {
        if (!frames_.empty() && !frames_.back().object) ++frames_.back().count;
    }

    // The JSON Pointer of the value just begun.
    std::string pointer() const {
        std::string p;
        for (const Frame& f : frames_) {
            p += '/';
            if (!f.object) {
                p += std::to_string(f.count - 1);
                continue;
            }
            for (const char c : f.key) p += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
        }
        return p;
    }

    bool wanted(const std::string& at) const {
        for (const std::string& where : flat_.where) {
            std::size_t i = 0, j = 0;
            bool same = true;
            while (same && i < where.size() && j < at.size()) {  // both at a '/'
                const std::size_t wi = std::min(where.find('/', i + 1), where.size());
                const std::size_t aj = std::min(at.find('/', j + 1), at.size());
                const std::string_view w(where.data() + i + 1, wi - i - 1),
                    a(at.data() + j + 1, aj - j - 1);
                const bool index = !a.empty() && std::all_of(a.begin(), a.end(), [](char c) {
                    return c >= '0' && c <= '9';
                });
                same = w == a || (w == "*" && index);
                i = wi;
                j = aj;
            }
            if (same && i == where.size() && j == at.size()) return true;
        }
        return false;
    }

    // The flat array turns out not to be rows of numbers: what it held so far goes into the
    // document (its open row too), and reading goes on as usual.
    void give_up() {
        capturing_ = false;
        frames_.push_back({false, {}, 0});
        dom_.start_array(kUnknownSize);
        std::size_t at = 0;
        for (const std::uint8_t width : rows_.widths) {
            ++frames_.back().count;
            dom_.start_array(kUnknownSize);
            for (std::size_t k = 0; k < width; ++k) dom_.number_float(rows_.values[at++], "");
            dom_.end_array();
        }
        if (in_row_) {
            ++frames_.back().count;
            frames_.push_back({false, {}, row_width_});
            dom_.start_array(kUnknownSize);
            for (std::size_t k = 0; k < row_width_; ++k) dom_.number_float(rows_.values[at++], "");
            in_row_ = false;
        }
        rows_ = {};
    }

    nlohmann::detail::json_sax_dom_parser<json> dom_;
    FlatNumberArrays& flat_;
    std::size_t max_depth_ = 0;
    std::vector<Frame> frames_;
    bool capturing_ = false, in_row_ = false;
    std::size_t row_width_ = 0;
    std::string capture_at_;
    FlatNumberArrays::Rows rows_;
};

}  // namespace

nlohmann::json parse_json_document(const std::string& text, const std::string& file,
                                   FlatNumberArrays* flat) {
    using nlohmann::json;
    check_depth(text, file);
    json document;
    try {
        if (flat != nullptr) {
            flat->found.clear();
            FlatSax sax(document, *flat);
            json::sax_parse(text, &sax);
        } else {
            document = json::parse(text);
        }
    } catch (const json::parse_error& e) {
        // nlohmann reports the byte just past the offending token; point at that token.
        const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
        std::string message = e.what();
        if (const auto at = message.find("syntax error"); at != std::string::npos)
            message = message.substr(at);
        throw InputError(file, JsonIndex(text, 0).location_of(offset), "invalid JSON: " + message);
    } catch (const json::out_of_range& e) {
        // A number too large for a double (e.g. 1e400): nlohmann names the token, not where.
        const std::string message = e.what();
        const auto open = message.find('\''), close = message.rfind('\'');
        if (open != std::string::npos && close > open) {
            const std::string token = message.substr(open + 1, close - open - 1);
            const auto at = text.find(token);
            throw InputError(
                file,
                at == std::string::npos ? SourceLocation{} : JsonIndex(text, 0).location_of(at),
                "number " + token + " is out of range (not finite as a double)");
        }
        throw InputError(file, {}, "invalid JSON: " + message);
    }
    check_strict(text, file, JsonIndex(text, 0));  // no value but the root: the checks need none
    return document;
}

SourceLocation JsonChecker::locate(const std::string& pointer) const {
    if (shallow_depth_ && static_cast<std::size_t>(
                              std::count(pointer.begin(), pointer.end(), '/')) <= *shallow_depth_) {
        if (!shallow_) shallow_.emplace(text_, *shallow_depth_);
        return shallow_->locate(pointer);
    }
    return index().locate(pointer);
}

const JsonIndex& JsonChecker::index() const {
    if (!index_) index_.emplace(text_);
    return *index_;
}

void JsonChecker::fail(const std::string& pointer, const std::string& message) const {
    throw InputError(file_, locate(pointer), message);
}

void JsonChecker::only_keys(const nlohmann::json& object, const std::string& pointer,
                            const std::set<std::string>& allowed) const {
    for (const auto& [key, value] : object.items()) {
        if (!allowed.count(key)) {
            std::string list;
            for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
            fail(pointer + "/" + key,
                 "unknown key \"" + key + "\" (expected one of: " + list + ")");
        }
    }
}

}  // namespace pathstream::host
