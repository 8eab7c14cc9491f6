#include "drawing_request.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <stdexcept>

#include "pathstream/host/path_formats.hpp"

namespace pathstream::host::serve {
namespace {

const std::string& text_value(const nlohmann::json& v, const std::string& key,
                              const std::set<std::string>& allowed) {
    if (!v.is_string()) throw std::invalid_argument(key + ": want a string");
    const std::string& s = v.get_ref<const std::string&>();
    if (!allowed.empty() && allowed.count(s) == 0)
        throw std::invalid_argument(key + ": '" + s + "' is not one of the choices");
    return s;
}

bool flag_value(const nlohmann::json& v, const std::string& key) {
    if (!v.is_boolean()) throw std::invalid_argument(key + ": want true or false");
    return v.get<bool>();
}

std::string number_text(double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

}  // namespace

std::string upload_file_name(const std::string& name) {
    std::string base = name.substr(std::min(name.size(), name.find_last_of("/\\") + 1));
    for (char& c : base) {
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-')
            c = '_';
    }
    while (!base.empty() && base.front() == '.') base.erase(0, 1);
    // The name is an argument of the commands the server runs: one starting with '-' would be
    // an option there (-h.csv: --help; -mfoo.csv: --machine).
    for (std::size_t i = 0; i < base.size() && base[i] == '-'; ++i) base[i] = '_';
    if (base.size() > 100) base = base.substr(base.size() - 100);
    const std::size_t dot = base.rfind('.');
    if (dot == std::string::npos || dot == 0 || format_of_file_name(base).empty()) {
        throw std::invalid_argument("'" + name + "': the name must end in " +
                                    path_extension_list());
    }
    return base;
}

std::vector<std::string> path_arguments(const nlohmann::json& options) {
    if (options.is_null()) return {};
    if (!options.is_object()) throw std::invalid_argument("options: want a JSON object");
    std::vector<std::string> args;
    static const std::set<std::string> papers = [] {
        std::set<std::string> p = {"area"};
        for (const char* n :
             {"a0", "a1", "a2", "a3", "a4", "a5", "a6", "letter", "legal", "tabloid"}) {
            p.insert(n);
            p.insert(std::string(n) + "-landscape");
        }
        return p;
    }();
    for (const auto& [key, v] : options.items()) {
        if (key == "fit") {
            if (v.is_string() && v.get_ref<const std::string&>().empty()) continue;
            args.push_back("--fit=" + text_value(v, key, papers));
        } else if (key == "margin") {
            if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0 ||
                v.get<double>() > 10000) {
                throw std::invalid_argument("margin: want mm from 0 to 10000");
            }
            if (v.get<double>() > 0) args.push_back("--margin=" + number_text(v.get<double>()));
        } else if (key == "align") {
            if (v.is_string() && v.get_ref<const std::string&>().empty()) continue;
            args.push_back("--align=" +
                           text_value(v, key,
                                      {"center", "top-left", "top", "top-right", "left", "right",
                                       "bottom-left", "bottom", "bottom-right"}));
        } else if (key == "origin") {
            args.push_back("--origin=" + text_value(v, key, {"top-left", "bottom-left"}));
        } else if (key == "rotate") {
            if (!v.is_number_integer() || (v.get<int>() != 0 && v.get<int>() != 90 &&
                                           v.get<int>() != 180 && v.get<int>() != 270)) {
                throw std::invalid_argument("rotate: want 0, 90, 180 or 270");
            }
            if (v.get<int>() != 0) args.push_back("--rotate=" + std::to_string(v.get<int>()));
        } else if (key == "flip_y") {
            if (flag_value(v, key)) args.push_back("--flip-y");
        } else if (key == "keep_order") {
            // The page's box asks for an order either way: G-code too is ordered when it is on.
            args.push_back(flag_value(v, key) ? "--keep-order" : "--order");
        } else if (key == "csv_closed") {
            if (flag_value(v, key)) args.push_back("--csv-closed");
        } else if (key == "pause") {
            args.push_back("--pause=" + text_value(v, key, {"pen", "layer", "none"}));
        } else if (key == "gcode_pen") {
            args.push_back("--gcode-pen=" +
                           text_value(v, key, {"z", "spindle", "motion", "machine", "auto"}));
        } else if (key == "csv_basis") {
            args.push_back("--csv-basis=" +
                           text_value(v, key, {"bspline", "catmull-rom", "bezier", "polyline"}));
        } else if (key == "layers") {
            if (!v.is_array() || v.size() > 256)
                throw std::invalid_argument("layers: want a list of at most 256 names");
            for (const nlohmann::json& layer : v) {
                if (!layer.is_string() || layer.get_ref<const std::string&>().empty() ||
                    layer.get_ref<const std::string&>().size() > 200) {
                    throw std::invalid_argument("layers: want names of 1 to 200 characters");
                }
                args.push_back("--layer=" + layer.get<std::string>());
            }
        } else {
            throw std::invalid_argument("options: unknown key '" + key + "'");
        }
    }
    return args;
}

}  // namespace pathstream::host::serve
