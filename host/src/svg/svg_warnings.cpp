// De-duplicated warnings of the SVG reader.
#include "pathstream/host/svg_warnings.hpp"

namespace pathstream::host::svg {

void WarningLog::add(const std::string& message, SourceLocation at) {
    const auto [it, fresh] = index_.emplace(message, entries_.size());
    if (fresh) entries_.push_back({message, at, 0});
    ++entries_[it->second].count;
}

std::vector<std::string> WarningLog::lines(const std::string& file) const {
    std::vector<std::string> out;
    for (const Entry& e : entries_) {
        std::string line = file;
        if (e.first.line > 0) {
            line += ":" + std::to_string(e.first.line) + ":" + std::to_string(e.first.column);
        }
        line += ": " + e.message;
        if (e.count > 1) line += " (" + std::to_string(e.count) + " times; the first here)";
        out.push_back(std::move(line));
    }
    return out;
}

std::size_t WarningLog::count(const std::string& message) const {
    const auto it = index_.find(message);
    return it == index_.end() ? 0 : entries_[it->second].count;
}

}  // namespace pathstream::host::svg
