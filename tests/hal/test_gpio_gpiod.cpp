// The libgpiod backend's errors where no GPIO exists (this machine and CI): every message names
// the chip and the line. The backend against a real kernel is tested in sim.gpio.vm.
#include <catch2/catch.hpp>
#include <string>

#include "pathstream/hal/gpio_gpiod.hpp"

using namespace pathstream::hal;

namespace {
std::string error_of(const GpioLineSpec& spec, bool output) {
    try {
        if (output) {
            (void)open_gpiod_output(spec, "test");
        } else {
            (void)open_gpiod_input(spec, "test");
        }
    } catch (const GpioError& e) {
        return e.what();
    }
    return "no error";
}
}  // namespace

TEST_CASE("gpiod backend: a missing chip is named with its line", "[gpio][gpiod]") {
    CHECK(error_of({"no-such-label", "estop", false, Bias::kAsIs}, false) ==
          "gpio no-such-label line \"estop\": no GPIO chip is named or labelled \"no-such-label\"");
    const std::string by_name = error_of({"gpiochip97", "3", true, Bias::kPullUp}, true);
    CHECK(by_name.rfind("gpio gpiochip97 line \"3\": cannot open the GPIO chip: ", 0) == 0);
    const std::string by_path = error_of({"/dev/gpiochip98", "enable", false, Bias::kAsIs}, true);
    CHECK(by_path.rfind("gpio /dev/gpiochip98 line \"enable\": cannot open the GPIO chip: ", 0) ==
          0);
    const std::string by_number = error_of({"99", "1", false, Bias::kAsIs}, false);
    CHECK(by_number.rfind("gpio 99 line \"1\": cannot open the GPIO chip: ", 0) == 0);
    CHECK(error_of({"", "1", false, Bias::kAsIs}, false) == "gpio  line \"1\": no chip given");
}
