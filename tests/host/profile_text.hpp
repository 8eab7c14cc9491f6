// Machine profile documents for the profile tests: two axes, one more top-level key on line 3,
// and the message a bad document is refused with.
#pragma once

#include <string>

#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::test {

/// The "axes" of a two-axis plotter, x and y, on lines 1 and 2 of the document.
inline constexpr const char* kTwoAxes =
    R"("axes": [{"name": "x", "max_velocity": 100, "max_acceleration": 1000},
                                {"name": "y", "max_velocity": 100, "max_acceleration": 1000}])";

/// The two axes and `"key": value` on line 3, which starts with `"key": ` (key length + 4
/// columns) before the value.
inline std::string with_key(const std::string& key, const std::string& value) {
    return std::string("{") + kTwoAxes + ",\n\"" + key + "\": " + value + "}";
}

/// The InputError parsing `text` as m.json gives ("m.json:L:C: ..."), or "no error".
inline std::string profile_error(const std::string& text) {
    try {
        host::parse_machine_profile(text, "m.json");
    } catch (const host::InputError& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace pathstream::test
