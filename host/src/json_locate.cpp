#include "pathstream/host/json_locate.hpp"

#include <cctype>
#include <optional>

namespace pathstream::host {
namespace {

// A forgiving scanner over text that nlohmann::json has already accepted: it only needs to
// find where each value starts, so it skips strings and scalars without validating them.
class Scanner {
public:
    Scanner(std::string_view text, const std::string& target) : text_(text), target_(target) {}

    std::optional<std::size_t> find() {
        skip_space();
        value("");
        return found_;
    }

private:
    void skip_space() {
        while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    }

    std::string string_token() {  // at '"'; returns the raw (unescaped enough) contents
        std::string out;
        ++pos_;
        while (pos_ < text_.size() && text_[pos_] != '"') {
            if (text_[pos_] == '\\' && pos_ + 1 < text_.size()) ++pos_;
            out += text_[pos_++];
        }
        ++pos_;
        return out;
    }

    static std::string escape(const std::string& key) {  // RFC 6901: ~ -> ~0, / -> ~1
        std::string out;
        for (char c : key) {
            if (c == '~') out += "~0";
            else if (c == '/') out += "~1";
            else out += c;
        }
        return out;
    }

    void value(const std::string& pointer) {
        if (found_) return;
        if (pointer == target_) {
            found_ = pos_;
            return;
        }
        if (pos_ >= text_.size()) return;
        const char c = text_[pos_];
        if (c == '{') {
            ++pos_;
            skip_space();
            while (pos_ < text_.size() && text_[pos_] != '}' && !found_) {
                const std::string key = string_token();
                skip_space();
                ++pos_;  // ':'
                skip_space();
                value(pointer + "/" + escape(key));
                skip_space();
                if (pos_ < text_.size() && text_[pos_] == ',') ++pos_;
                skip_space();
            }
            ++pos_;
        } else if (c == '[') {
            ++pos_;
            skip_space();
            for (std::size_t i = 0; pos_ < text_.size() && text_[pos_] != ']' && !found_; ++i) {
                value(pointer + "/" + std::to_string(i));
                skip_space();
                if (pos_ < text_.size() && text_[pos_] == ',') ++pos_;
                skip_space();
            }
            ++pos_;
        } else if (c == '"') {
            string_token();
        } else {
            while (pos_ < text_.size() && text_[pos_] != ',' && text_[pos_] != ']' &&
                   text_[pos_] != '}' && !std::isspace(static_cast<unsigned char>(text_[pos_]))) {
                ++pos_;
            }
        }
    }

    std::string_view text_;
    const std::string& target_;
    std::size_t pos_ = 0;
    std::optional<std::size_t> found_;
};

}  // namespace

SourceLocation locate_offset(std::string_view text, std::size_t offset) {
    SourceLocation at{1, 1};
    for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++at.line;
            at.column = 1;
        } else {
            ++at.column;
        }
    }
    return at;
}

SourceLocation locate_json_pointer(std::string_view text, const std::string& pointer) {
    const auto offset = Scanner(text, pointer).find();
    return offset ? locate_offset(text, *offset) : SourceLocation{};
}

}  // namespace pathstream::host
