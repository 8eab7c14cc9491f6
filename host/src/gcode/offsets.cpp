// Program -> machine coordinates: coordinate systems G54..G59.3 and G10 L2/L20, the G92
// offset, tool length offsets G43/G43.1/G49; G28/G30 homing moves (docs/formats-gcode.md,
// "Offsets"). Positions and offsets live in LinuxCNC's numbered parameters, in mm.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "interpreter.hpp"

namespace pathstream::host::gcode {

namespace {

// LinuxCNC's parameters (X Y Z A B C U V W each).
constexpr long kG28Position = 5161;
constexpr long kG30Position = 5181;
constexpr long kG92Applied = 5210;
constexpr long kG92Offset = 5211;
constexpr long kCurrentSystem = 5220;  // 1 (G54) .. 9 (G59.3)
constexpr long kSystemOffsets = 5221;  // G54's X; +20 per system; +9: its rotation R
constexpr long kSystemStride = 20;
constexpr long kAppliedToolOffsets = 5081;  // the offsets G43 applies

ParameterRef numbered(long n) {
    return ParameterRef{n, {}};
}

const char* system_name(std::size_t system) {
    static const char* const names[] = {"G54", "G55",   "G56",   "G57",  "G58",
                                        "G59", "G59.1", "G59.2", "G59.3"};
    return names[system];
}

}  // namespace

double Interpreter::offset(std::size_t axis) const {
    const long base = kSystemOffsets + kSystemStride * static_cast<long>(system_);
    return *parameters_.get(numbered(base + static_cast<long>(axis))) + g92_[axis] +
           tool_offset_[axis];
}

void Interpreter::load_tool() {
    if (selected_tool_ < 0) return;
    loaded_tool_ = selected_tool_;
    parameters_.set(numbered(5400), static_cast<double>(loaded_tool_));
    const ToolEntry* entry = tools_.find(loaded_tool_);
    for (std::size_t a = 0; a < kAxisCount; ++a) {
        parameters_.set(numbered(5401 + static_cast<long>(a)), entry ? entry->offsets[a] : 0.0);
    }
    parameters_.set(numbered(5410), entry ? entry->diameter : 0.0);
}

void Interpreter::offsets_modes(const Command& c) {
    if (c.coordinate_system) {
        const std::size_t system = *c.coordinate_system;
        const long rotation = kSystemOffsets + kSystemStride * static_cast<long>(system) + 9;  // R
        if (*parameters_.get(numbered(rotation)) != 0) {
            fail(c.coordinate_system_at, std::string(system_name(system)) + " is rotated (#" +
                                             std::to_string(rotation) +
                                             "): coordinate system rotation is not supported");
        }
        system_ = system;
        parameters_.set(numbered(kCurrentSystem), static_cast<double>(system + 1));
    }
    if (!c.tool_length) return;
    switch (*c.tool_length) {
        case ToolLength::kCancel:
            tool_offset_ = {};
            break;
        case ToolLength::kTable: {
            // Without H (or H0), the tool in the spindle: the one the last M6 loaded.
            const Word* h = c.value('H');
            if (h && (h->value != std::floor(h->value) || h->value < 0)) {
                fail(h->at, "H must be a whole tool number >= 0");
            }
            const SourceLocation h_at = h ? h->at : c.tool_length_at;
            const std::string h_text = h ? "H" + h->text : std::string("(no H)");
            long tool = h ? static_cast<long>(h->value) : 0;
            if (tool == 0) tool = std::max(loaded_tool_, 0L);
            if (tool == 0) {
                // As LinuxCNC: tool 0 is no tool, whose offsets are 0.
                tool_offset_ = {};
                break;
            }
            if (tools_.empty()) {
                fail(h_at, "G43 " + h_text + ": no tool table (give one with --tool-table)");
            }
            const ToolEntry* entry = tools_.find(tool);
            if (!entry) {
                fail(h_at, "G43 " + h_text + ": tool " + std::to_string(tool) +
                               " is not in the tool table " + tools_.source());
            }
            tool_offset_ = entry->offsets;
            break;
        }
        case ToolLength::kDynamic:
            // G43.1: the block's axis words replace those axes' offsets, nothing moves.
            for (std::size_t a = 0; a < kAxisCount; ++a) {
                if (const Word* w = c.value(kAxisLetters[a])) tool_offset_[a] = axis_value(*w, a);
            }
            break;
    }
    for (std::size_t a = 0; a < kAxisCount; ++a) {
        parameters_.set(numbered(kAppliedToolOffsets + static_cast<long>(a)), tool_offset_[a]);
    }
}

void Interpreter::non_modal(const Command& c) {
    auto store_g92 = [&] {
        for (std::size_t a = 0; a < kAxisCount; ++a)
            parameters_.set(numbered(kG92Offset + static_cast<long>(a)), g92_[a]);
    };
    bool any_axis = false;
    for (const char letter : kAxisLetters) any_axis = any_axis || c.value(letter);
    switch (c.non_modal) {
        case NonModal::kSetOffset: {
            if (!any_axis) fail(c.non_modal_at, "G92 needs at least one axis word");
            // The current point gets the given coordinates: machine = program + offsets.
            for (std::size_t a = 0; a < kAxisCount; ++a) {
                const Word* w = c.value(kAxisLetters[a]);
                if (!w) continue;
                g92_[a] = 0;
                g92_[a] = pos_[a] - offset(a) - axis_value(*w, a);
                if (a == kZ) z_known_ = true;
            }
            store_g92();
            parameters_.set(numbered(kG92Applied), 1);
            break;
        }
        case NonModal::kClearOffset:
        case NonModal::kSuspendOffset:
            g92_ = {};
            if (c.non_modal == NonModal::kClearOffset) store_g92();
            parameters_.set(numbered(kG92Applied), 0);
            break;
        case NonModal::kRestoreOffset:
            for (std::size_t a = 0; a < kAxisCount; ++a)
                g92_[a] = *parameters_.get(numbered(kG92Offset + static_cast<long>(a)));
            parameters_.set(numbered(kG92Applied), 1);
            break;
        case NonModal::kSetHome:
        case NonModal::kSetHome2: {
            const long base = c.non_modal == NonModal::kSetHome ? kG28Position : kG30Position;
            for (std::size_t a = 0; a < kAxisCount; ++a)
                parameters_.set(numbered(base + static_cast<long>(a)), pos_[a]);
            break;
        }
        case NonModal::kHome:
        case NonModal::kHome2: {
            // As LinuxCNC: through the given point, then to the stored position, both at rapid;
            // with axis words only those axes move.
            const long base = c.non_modal == NonModal::kHome ? kG28Position : kG30Position;
            const SourceLocation at = c.non_modal_at;
            travel(targets(c, false), at);
            Axes home = pos_;
            for (std::size_t a = 0; a < kAxisCount; ++a) {
                if (any_axis && !c.value(kAxisLetters[a])) continue;
                const long n = base + static_cast<long>(a);
                const double v = *parameters_.get(numbered(n));
                if (std::fabs(v) > 1e6) {
                    fail(at, "#" + std::to_string(n) + " " + number_text(v) +
                                 " is out of range (|value| <= 1e+06)");
                }
                if (!on_path(a) && a != kZ && v != pos_[a]) {
                    fail(at, "#" + std::to_string(n) + " moves axis " +
                                 std::string(1, kAxisLetters[a]) +
                                 ", which is not one of this machine's axes (" + options_.axes +
                                 ")");
                }
                home[a] = v;
            }
            if (!any_axis || c.value('Z')) z_known_ = true;
            travel(home, at);
            break;
        }
        case NonModal::kSetCoordinates:
            set_coordinates(c);
            break;
        default:
            break;
    }
}

void Interpreter::set_coordinates(const Command& c) {
    const Word *l = c.value('L'), *p = c.value('P'), *r = c.value('R');
    if (!l || (l->value != 2 && l->value != 20)) {
        fail(l ? l->at : c.non_modal_at,
             l && (l->value == 1 || l->value == 10 || l->value == 11)
                 ? "G10 L" + l->text + " edits the tool table: edit the tool table file instead"
                 : std::string("G10 needs L2 or L20 (set a coordinate system)"));
    }
    if (!p || p->value != std::floor(p->value) || p->value < 0 || p->value > 9) {
        fail(p ? p->at : c.non_modal_at,
             "G10 L" + l->text + " needs P from 0 (the current system) to 9 (G59.3)");
    }
    if (r && l->value == 20) fail(r->at, "R is not allowed with G10 L20");
    if (r && r->value != 0) fail(r->at, "coordinate system rotation (G10 R) is not supported");
    const std::size_t system = p->value == 0 ? system_ : static_cast<std::size_t>(p->value) - 1;
    const long base = kSystemOffsets + kSystemStride * static_cast<long>(system);
    for (std::size_t a = 0; a < kAxisCount; ++a) {
        const Word* w = c.value(kAxisLetters[a]);
        if (!w) continue;
        const ParameterRef ref = numbered(base + static_cast<long>(a));
        double v = axis_value(*w, a);
        if (l->value == 20) {
            // L20: the origin such that the machine's current point has the given coordinates.
            v = pos_[a] - g92_[a] - tool_offset_[a] - v;
        }
        parameters_.set(ref, v);
        if (a == kZ && system == system_) z_known_ = z_known_ || l->value == 20;
    }
}

}  // namespace pathstream::host::gcode
