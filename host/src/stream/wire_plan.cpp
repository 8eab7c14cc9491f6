#include "pathstream/host/wire_plan.hpp"

#include <stdexcept>
#include <string>

#include "pathstream/device/wire_span.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host {

WirePlan encode_wire_plan(const Plan& plan) {
    if (plan.spans.empty()) throw std::invalid_argument("the plan has no spans");
    WirePlan out;
    out.axes = static_cast<unsigned>(plan.spans.front().control.size());
    if (out.axes < 1 || out.axes > 8) throw std::invalid_argument("1 to 8 axes");
    for (unsigned a = 0; a < out.axes; ++a) out.start[a] = plan.spans.front().control[a][0];
    std::int32_t previous_tangent[8] = {};
    out.prefix_ticks.push_back(0);
    for (std::size_t i = 0; i < plan.spans.size(); ++i) {
        const CoreSpan& c = plan.spans[i];
        if (c.basis != Basis::kHermite) throw std::invalid_argument("only Hermite spans stream (planned paths are)");
        if (c.control.size() != out.axes) {
            throw std::invalid_argument("plan span " + std::to_string(i) + " has another axis count");
        }
        device::WireSpan w;
        w.ticks = c.ticks;
        w.outputs = c.pen_down ? kOutputPenDown : std::uint8_t{0};
        bool continues = i > 0;
        for (unsigned a = 0; a < out.axes; ++a) {
            if (i > 0 && c.control[a][0] != plan.spans[i - 1].control[a][1]) {
                throw std::invalid_argument("plan span " + std::to_string(i) +
                                            " does not start where the previous one ends");
            }
            w.end[a] = c.control[a][1];
            w.start_tangent[a] = c.control[a][2];
            w.end_tangent[a] = c.control[a][3];
            continues = continues && c.control[a][2] == previous_tangent[a];
            previous_tangent[a] = c.control[a][3];
        }
        w.flags = continues ? device::kWireContinueTangent : 0;
        if (c.pause_after) {
            for (unsigned a = 0; a < out.axes; ++a) {
                if (c.control[a][3] != 0)
                    throw std::invalid_argument("plan span " + std::to_string(i) +
                                                " is followed by a pause but does not end at rest");
            }
            w.flags = static_cast<std::uint8_t>(w.flags | device::kWirePause);
        }
        if (i + 1 == plan.spans.size()) {
            // The plan is one job: its last span marks the end, where the device idles.
            for (unsigned a = 0; a < out.axes; ++a) {
                if (c.control[a][3] != 0)
                    throw std::invalid_argument("the plan does not end at rest");
            }
            w.flags = static_cast<std::uint8_t>(w.flags | device::kWireJobEnd);
        }
        std::vector<std::uint8_t> bytes(device::wire_span_bytes(out.axes, continues));
        if (device::encode_wire_span(w, out.axes, bytes.data(), bytes.size()) != bytes.size()) {
            throw std::invalid_argument("span " + std::to_string(i) + " cannot be encoded");
        }
        out.spans.push_back(std::move(bytes));
        out.prefix_ticks.push_back(out.prefix_ticks.back() + c.ticks);
    }
    return out;
}

}  // namespace pathstream::host
