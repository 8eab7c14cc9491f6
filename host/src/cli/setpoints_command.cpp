#include "setpoints_command.hpp"

#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "pathstream/host/atomic_file.hpp"
#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/input_error.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/setpoint_stream.hpp"

namespace pathstream::host {
namespace {

constexpr const char* kAxisNames[] = {"x", "y", "z", "a", "b", "c", "u", "v"};

struct RunSummary {
    std::uint64_t ticks = 0;
    std::size_t spans = 0;
    std::uint64_t verified = 0;
};

/// Feeds the spans through the core's SetpointStream exactly as a device would (queue from
/// a task, one tick() per timer interrupt) and writes one CSV row per tick. Every setpoint is
/// also checked against the core's 128-bit Horner evaluation of the same span.
template <unsigned Axes>
RunSummary stream_through_core(const std::vector<CoreSpan>& spans, std::ostream& csv) {
    Lsb start[Axes];
    for (unsigned a = 0; a < Axes; ++a) start[a] = core_value_at(spans.front(), a, 0);
    // The host may allocate: one stream object (inline storage, tens of kB) on the heap.
    const auto holder = std::make_unique<SetpointStream<Axes, 64>>(start);
    SetpointStream<Axes, 64>& stream = *holder;

    csv << "tick,span,subpath,pen";
    for (unsigned a = 0; a < Axes; ++a) csv << ',' << kAxisNames[a];
    csv << '\n';

    RunSummary summary;
    summary.spans = spans.size();
    std::size_t next_to_push = 0;
    std::uint32_t tick_in_span = 0;
    Lsb out[Axes];
    for (;;) {
        while (next_to_push < spans.size() && stream.free_slots() > 0) {
            Span<Axes> s;
            s.basis = spans[next_to_push].basis;
            s.ticks = spans[next_to_push].ticks;
            s.tag = static_cast<std::uint32_t>(next_to_push);
            for (unsigned a = 0; a < Axes; ++a) {
                for (int i = 0; i < 4; ++i) s.control[a][i] = spans[next_to_push].control[a][static_cast<std::size_t>(i)];
            }
            if (const Status st = stream.push(s); st != Status::kOk) {
                throw std::logic_error(std::string("core refused a validated span: ") + status_name(st));
            }
            ++next_to_push;
        }
        const std::size_t current = stream.spans_completed();
        if (stream.tick(out) == TickState::kIdle) break;
        const CoreSpan& span = spans[current];
        csv << summary.ticks << ',' << current << ',' << span.subpath << ',' << (span.pen_down ? 1 : 0);
        for (unsigned a = 0; a < Axes; ++a) {
            csv << ',' << out[a];
            if (out[a] != core_value_at(span, a, tick_in_span)) {
                std::ostringstream m;
                m << "forward differencing and Horner disagree at tick " << summary.ticks;
                throw std::logic_error(m.str());
            }
            ++summary.verified;
        }
        csv << '\n';
        ++summary.ticks;
        tick_in_span = stream.spans_completed() != current ? 0 : tick_in_span + 1;
    }
    // The last row: the path's end point, held once the queue has run dry.
    csv << summary.ticks << ',' << spans.size() - 1 << ',' << spans.back().subpath << ','
        << (spans.back().pen_down ? 1 : 0);
    for (unsigned a = 0; a < Axes; ++a) csv << ',' << out[a];
    csv << '\n';
    ++summary.ticks;
    return summary;
}

template <unsigned... A>
RunSummary dispatch(std::size_t axes, const std::vector<CoreSpan>& spans, std::ostream& csv,
                    std::integer_sequence<unsigned, A...>) {
    RunSummary r;
    const bool found = ((axes == A + 1 ? (r = stream_through_core<A + 1>(spans, csv), true) : false) || ...);
    if (!found) throw std::logic_error("unsupported axis count");
    return r;
}

}  // namespace

void add_setpoints_command(CLI::App& app, SetpointsOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "setpoints",
        "Run a path through the firmware core (exact forward differencing) and write every "
        "tick's setpoints as CSV: tick,span,subpath,pen,x,y,... in LSB");
    cmd->add_option("file", o.input, "path file (JSON, see docs/formats.md)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--out,-o", o.output, "CSV output file (default: standard output)");
    cmd->add_option("--ticks-per-span", o.ticks_per_span, "ticks each span lasts")
        ->capture_default_str()
        ->check(CLI::Range(1u, kMaxSpanTicks));
    cmd->add_option("--lsb", o.mm_per_lsb, "millimetres per LSB (position resolution)")
        ->capture_default_str()
        ->check(CLI::Range(1e-6, 10.0));
}

int run_setpoints(const SetpointsOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    const Path path = load_json_path(o.input);
    const std::vector<CoreSpan> spans = uniform_core_spans(path, o.input, o.mm_per_lsb, o.ticks_per_span);

    RunSummary summary;
    if (o.output.empty()) {
        summary = dispatch(path.axes, spans, std::cout, std::make_integer_sequence<unsigned, 8>{});
        std::cout.flush();
        if (!std::cout) throw std::runtime_error("standard output: write failed");
    } else {
        AtomicFile file(o.output);
        summary = dispatch(path.axes, spans, file.stream(), std::make_integer_sequence<unsigned, 8>{});
        file.commit();
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::cerr << "pathstream setpoints: " << o.input << ": " << path.subpaths.size() << " subpath(s), "
              << summary.spans << " spans x " << o.ticks_per_span << " ticks, " << path.axes
              << " axes -> " << summary.ticks << " ticks"
              << (o.output.empty() ? "" : " written to " + o.output) << "\n"
              << "  every setpoint (" << summary.verified
              << ") equals the core's 128-bit Horner value: exact, rounded once; " << ms << " ms\n";
    return 0;
}

}  // namespace pathstream::host
