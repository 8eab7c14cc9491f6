// Line and column of byte offsets, each lookup in bounded time: rescanning from the start of
// the text for every element made reading quadratic in the file's size.
#include <algorithm>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {
namespace {

// Advances `at` over byte `c`: a newline starts a line; UTF-8 continuation bytes add nothing.
void step(SourceLocation& at, unsigned char c) {
    if (c == '\n') {
        ++at.line;
        at.column = 1;
    } else if ((c & 0xC0) != 0x80) {
        ++at.column;
    }
}

}  // namespace

TextLocator::TextLocator(std::string_view text) : text_(text) {
    begin_ = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
    checkpoints_.reserve(text.size() / kStride + 1);
    SourceLocation at{1, 1};
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (i % kStride == 0) checkpoints_.push_back(at);
        if (i >= begin_) step(at, static_cast<unsigned char>(text[i]));
    }
    if (checkpoints_.empty()) checkpoints_.push_back(at);
}

SourceLocation TextLocator::locate(std::size_t offset) {
    ++lookups_;
    offset = std::min(offset, text_.size());
    const std::size_t k = std::min(offset / kStride, checkpoints_.size() - 1);
    SourceLocation at = checkpoints_[k];
    for (std::size_t i = k * kStride; i < offset; ++i) {
        ++scanned_;
        if (i >= begin_) step(at, static_cast<unsigned char>(text_[i]));
    }
    return at;
}

}  // namespace pathstream::host::svg
