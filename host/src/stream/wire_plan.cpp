#include "pathstream/host/wire_plan.hpp"

#include <stdexcept>
#include <string>

#include "pathstream/device/wire_span.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host {

std::vector<std::uint8_t> WireEncoder::encode(const CoreSpan& c, bool last) {
    const std::size_t i = index_;
    if (i == 0) {
        axes_ = static_cast<unsigned>(c.control.size());
        if (axes_ < 1 || axes_ > 8) throw std::invalid_argument("1 to 8 axes");
    }
    if (c.basis != Basis::kHermite)
        throw std::invalid_argument("only Hermite spans stream (planned paths are)");
    if (c.control.size() != axes_) {
        throw std::invalid_argument("plan span " + std::to_string(i) + " has another axis count");
    }
    device::WireSpan w;
    w.ticks = c.ticks;
    w.outputs = span_outputs(c);
    bool continues = i > 0;
    for (unsigned a = 0; a < axes_; ++a) {
        if (i > 0 && c.control[a][0] != previous_end_[a]) {
            throw std::invalid_argument("plan span " + std::to_string(i) +
                                        " does not start where the previous one ends");
        }
        w.end[a] = c.control[a][1];
        w.start_tangent[a] = c.control[a][2];
        w.end_tangent[a] = c.control[a][3];
        continues = continues && c.control[a][2] == previous_tangent_[a];
    }
    w.flags = continues ? device::kWireContinueTangent : 0;
    if (c.pause_after) {
        for (unsigned a = 0; a < axes_; ++a) {
            if (c.control[a][3] != 0)
                throw std::invalid_argument("plan span " + std::to_string(i) +
                                            " is followed by a pause but does not end at rest");
        }
        w.flags = static_cast<std::uint8_t>(w.flags | device::kWirePause);
    }
    if (last) {
        // The plan is one job: its last span marks the end, where the device idles.
        for (unsigned a = 0; a < axes_; ++a) {
            if (c.control[a][3] != 0) throw std::invalid_argument("the plan does not end at rest");
        }
        w.flags = static_cast<std::uint8_t>(w.flags | device::kWireJobEnd);
    }
    std::vector<std::uint8_t> bytes(device::wire_span_bytes(axes_, continues));
    if (device::encode_wire_span(w, axes_, bytes.data(), bytes.size()) != bytes.size()) {
        throw std::invalid_argument("span " + std::to_string(i) + " cannot be encoded");
    }
    for (unsigned a = 0; a < axes_; ++a) {
        previous_end_[a] = c.control[a][1];
        previous_tangent_[a] = c.control[a][3];
    }
    ++index_;
    return bytes;
}

WirePlan encode_wire_plan(const Plan& plan) {
    if (plan.spans.empty()) throw std::invalid_argument("the plan has no spans");
    WirePlan out;
    WireEncoder encoder;
    out.prefix_ticks.push_back(0);
    for (std::size_t i = 0; i < plan.spans.size(); ++i) {
        out.spans.push_back(encoder.encode(plan.spans[i], i + 1 == plan.spans.size()));
        out.prefix_ticks.push_back(out.prefix_ticks.back() + plan.spans[i].ticks);
    }
    out.axes = static_cast<unsigned>(plan.spans.front().control.size());
    for (unsigned a = 0; a < out.axes; ++a) out.start[a] = plan.spans.front().control[a][0];
    return out;
}

}  // namespace pathstream::host
