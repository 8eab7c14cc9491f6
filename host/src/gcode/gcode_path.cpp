// parse_gcode_path / load_gcode_path: lines -> blocks -> commands -> path.
#include "pathstream/host/gcode_path.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "command.hpp"
#include "interpreter.hpp"
#include "lexer.hpp"
#include "pathstream/host/input_error.hpp"

namespace pathstream::host {

Path parse_gcode_path(const std::string& text, const std::string& file,
                      const GcodeOptions& options) {
    if (!std::isfinite(options.z_down_max)) {
        throw std::invalid_argument("GcodeOptions::z_down_max must be finite");
    }
    if (!(options.arc_tolerance_mm >= 1e-6) || !std::isfinite(options.arc_tolerance_mm)) {
        throw std::invalid_argument("GcodeOptions::arc_tolerance_mm must be finite and >= 1e-6");
    }
    gcode::Interpreter interpreter(file, options);
    std::string_view rest(text);
    if (rest.substr(0, 3) == "\xEF\xBB\xBF") rest.remove_prefix(3);  // UTF-8 byte order mark
    for (std::size_t line = 1; !rest.empty(); ++line) {
        const std::size_t end = rest.find('\n');
        std::string_view current = rest.substr(0, end);
        rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
        if (!current.empty() && current.back() == '\r') current.remove_suffix(1);
        const auto block = gcode::lex_line(current, line, file);
        if (!block) continue;
        if (!interpreter.execute(gcode::decode_block(*block, file))) break;
    }
    return interpreter.finish();
}

Path load_gcode_path(const std::string& file, const GcodeOptions& options) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return parse_gcode_path(buffer.str(), file, options);
}

}  // namespace pathstream::host
