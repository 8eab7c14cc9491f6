#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pathstream/host/ring_down.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {
namespace {

/// Most samples a ring-down file may hold: 2 million (over half an hour at 1 kHz), so a huge
/// or hostile file costs bounded memory.
constexpr std::size_t kMaxSamples = 2000000;

struct Cell {
    std::string text;
    std::size_t column;  // 1-based
};

std::vector<Cell> cells(const std::string& line) {
    std::vector<Cell> out;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = line.find(',', begin);
        const std::size_t end = comma == std::string::npos ? line.size() : comma;
        std::size_t a = begin, b = end;
        while (a < b && (line[a] == ' ' || line[a] == '\t')) ++a;
        while (b > a && (line[b - 1] == ' ' || line[b - 1] == '\t' || line[b - 1] == '\r')) --b;
        out.push_back({line.substr(a, b - a), a + 1});
        if (comma == std::string::npos) break;
        begin = comma + 1;
    }
    return out;
}

}  // namespace

RingDownSamples load_ring_down_csv(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open the ring-down file");
    std::ostringstream text;
    text << in.rdbuf();
    return parse_ring_down_csv(text.str(), file);
}

RingDownSamples parse_ring_down_csv(const std::string& text, const std::string& file) {
    std::istringstream in(text);
    RingDownSamples s;
    std::size_t time_column = 0, value_column = 0, columns = 0, line_number = 0;
    bool header = false;
    for (std::string line; std::getline(in, line);) {
        ++line_number;
        if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos)
            continue;
        const std::vector<Cell> row = cells(line);
        if (!header) {
            bool time = false, value = false;
            for (std::size_t c = 0; c < row.size(); ++c) {
                if (row[c].text == "time") {
                    time_column = c;
                    time = true;
                } else if (row[c].text == "position" || row[c].text == "acceleration") {
                    value_column = c;
                    value = true;
                } else {
                    throw InputError(file, {line_number, row[c].column},
                                     "unknown column \"" + row[c].text +
                                         "\" (expected time and one of position, acceleration)");
                }
            }
            if (!time || !value) {
                throw InputError(file, {line_number, 1},
                                 "the header needs a time column and a position or acceleration "
                                 "column");
            }
            columns = row.size();
            header = true;
            continue;
        }
        if (row.size() != columns) {
            throw InputError(
                file, {line_number, 1},
                std::to_string(row.size()) + " columns, the header has " + std::to_string(columns));
        }
        if (s.time.size() == kMaxSamples)
            throw InputError(file, {line_number, 1}, "more than 2,000,000 samples");
        double v[2] = {};
        const std::size_t at[2] = {time_column, value_column};
        for (int k = 0; k < 2; ++k) {
            const Cell& c = row[at[k]];
            char* end = nullptr;
            v[k] = std::strtod(c.text.c_str(), &end);
            if (c.text.empty() || end != c.text.c_str() + c.text.size() || !std::isfinite(v[k]))
                throw InputError(file, {line_number, c.column},
                                 "\"" + c.text + "\" is not a number");
        }
        if (!s.time.empty() && !(v[0] > s.time.back())) {
            throw InputError(file, {line_number, row[time_column].column},
                             "time must increase from one sample to the next");
        }
        s.time.push_back(v[0]);
        s.value.push_back(v[1]);
    }
    if (!header) throw InputError(file, {line_number, 1}, "no header line (time,position)");
    return s;
}

}  // namespace pathstream::host
