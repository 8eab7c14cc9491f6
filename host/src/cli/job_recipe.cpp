#include "job_recipe.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pathstream/host/job_journal.hpp"
#include "pathstream/machine/atomic_file.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {

const char* planner_identity() {
    return "pathstream 0.1.0";
}

std::string file_content_hash(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream whole;
    whole << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return content_hash(whole.str());
}

JobRecipe save_job_recipe(JobRequest& path, const std::string& machine_file,
                          const std::optional<std::vector<double>>& lead_in_from,
                          const std::string& copy) {
    std::string format;
    const std::string text = read_path_input(path, format);
    if (format.empty())
        throw InputError(path_display_name(path.file), {},
                         "standard input is empty: no path to read");
    AtomicFile f(copy);
    f.stream().write(text.data(), static_cast<std::streamsize>(text.size()));
    f.commit();
    JobRecipe r;
    r.path = path;
    r.path.file = copy;
    r.path.format = format;
    if (path.file == "-") path = r.path;
    r.lead_in_from = lead_in_from;
    r.input_hash = content_hash(text);
    r.machine_hash = file_content_hash(machine_file);
    r.planner = planner_identity();
    return r;
}

std::string job_recipe_json(const JobRecipe& r) {
    const JobRequest& p = r.path;
    nlohmann::json d;
    d["input"] = p.file;
    d["input_hash"] = r.input_hash;
    d["machine_hash"] = r.machine_hash;
    d["planner"] = r.planner;
    d["format"] = p.format;
    d["csv_basis"] = p.csv_basis;
    d["csv_closed"] = p.csv_closed;
    d["gcode_pen"] = p.gcode_pen;
    d["gcode_z_down"] = p.gcode_z_down;
    d["gcode_tool_table"] = p.gcode_tool_table;
    d["gcode_subroutine_path"] = p.gcode_subroutine_path;
    d["gcode_ignore"] = p.gcode_ignore;
    d["tolerance"] = p.tolerance;
    d["rotate"] = p.placement.rotate;
    d["flip_y"] = p.placement.flip_y;
    d["scale"] = p.placement.scale;
    d["fit"] = p.placement.fit;
    d["margin"] = p.placement.margin;
    d["align"] = p.placement.align;
    d["origin"] = p.placement.origin;
    d["translate"] = p.translate;
    d["keep_order"] = p.keep_order;
    d["order"] = p.order;
    d["keep_order_by_default"] = p.keep_order_by_default;
    d["merge_tolerance"] = p.merge_tolerance;
    d["order_start"] = p.order_start;
    d["layers"] = p.layers;
    d["pause"] = p.pause;
    d["lead_in_from"] = r.lead_in_from ? nlohmann::json(*r.lead_in_from) : nlohmann::json(nullptr);
    // Doubles are written shortest round-trip: the options read back bit for bit.
    return d.dump();
}

JobRecipe parse_job_recipe(const std::string& json, const std::string& journal) {
    const nlohmann::json d = nlohmann::json::parse(json, nullptr, false);
    if (!d.is_object()) throw InputError(journal, {}, "\"replan\" is not an object");
    JobRecipe r;
    JobRequest& p = r.path;
    const auto get = [&](const char* key, auto& out) {
        if (!d.contains(key))
            throw InputError(journal, {}, std::string("\"replan\" has no \"") + key + "\"");
        try {
            d.at(key).get_to(out);
        } catch (const nlohmann::json::exception&) {
            throw InputError(journal, {},
                             std::string("\"replan\": \"") + key + "\" has the wrong type");
        }
    };
    get("input", p.file);
    get("input_hash", r.input_hash);
    get("machine_hash", r.machine_hash);
    get("planner", r.planner);
    get("format", p.format);
    get("csv_basis", p.csv_basis);
    get("csv_closed", p.csv_closed);
    get("gcode_pen", p.gcode_pen);
    get("gcode_z_down", p.gcode_z_down);
    get("gcode_tool_table", p.gcode_tool_table);
    get("gcode_subroutine_path", p.gcode_subroutine_path);
    get("gcode_ignore", p.gcode_ignore);
    get("tolerance", p.tolerance);
    get("rotate", p.placement.rotate);
    get("flip_y", p.placement.flip_y);
    get("scale", p.placement.scale);
    get("fit", p.placement.fit);
    get("margin", p.placement.margin);
    get("align", p.placement.align);
    get("origin", p.placement.origin);
    get("translate", p.translate);
    get("keep_order", p.keep_order);
    if (d.contains("order")) get("order", p.order);
    if (d.contains("keep_order_by_default")) get("keep_order_by_default", p.keep_order_by_default);
    get("merge_tolerance", p.merge_tolerance);
    get("order_start", p.order_start);
    get("layers", p.layers);
    get("pause", p.pause);
    if (!d.contains("lead_in_from"))
        throw InputError(journal, {}, "\"replan\" has no \"lead_in_from\"");
    if (!d["lead_in_from"].is_null()) {
        std::vector<double> from;
        get("lead_in_from", from);
        r.lead_in_from = from;
    }
    return r;
}

}  // namespace pathstream::host
