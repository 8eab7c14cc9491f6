// The ring-down CSV reader (pathstream calibrate --csv) and the fit behind it: samples with
// finite values and increasing times, or an InputError naming the file; the fit gives a finite
// frequency and damping or refuses with std::invalid_argument.
#include <cmath>
#include <stdexcept>

#include "fuzz_support.hpp"
#include "pathstream/host/ring_down.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    const std::string text = fuzz::text_of(data, size);
    host::RingDownSamples samples;
    try {
        samples = host::parse_ring_down_csv(text, "r.csv");
    } catch (const host::InputError& e) {
        if (std::string(e.what()).rfind("r.csv:", 0) != 0)
            fuzz::violated(std::string("message: ") + e.what());
        return 0;
    } catch (const std::exception& e) {
        fuzz::violated(std::string("not an InputError: ") + e.what());
    }
    if (samples.time.size() != samples.value.size()) fuzz::violated("columns of two lengths");
    for (std::size_t i = 0; i < samples.time.size(); ++i) {
        if (!std::isfinite(samples.time[i]) || !std::isfinite(samples.value[i]))
            fuzz::violated("a sample that is not finite");
        if (i > 0 && !(samples.time[i] > samples.time[i - 1]))
            fuzz::violated("time not increasing");
    }
    try {
        const host::RingDown r = host::fit_ring_down(samples);
        if (!std::isfinite(r.frequency_hz) || !(r.frequency_hz > 0) || !std::isfinite(r.damping) ||
            r.damping < 0 || r.damping > 1) {
            fuzz::violated("a fit that is not a mode");
        }
    } catch (const std::invalid_argument&) {
    } catch (const std::exception& e) {
        fuzz::violated(std::string("the fit threw something else: ") + e.what());
    }
    return 0;
}
