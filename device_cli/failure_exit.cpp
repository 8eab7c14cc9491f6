#include "failure_exit.hpp"

#include <iostream>
#include <stdexcept>
#include <system_error>

#include "pathstream/hal/gpio_gpiod.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/machine/exit_codes.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::device_cli {

int failure_exit(const std::exception_ptr& failure) {
    try {
        std::rethrow_exception(failure);
    } catch (const host::InputError& e) {
        std::cerr << e.what() << '\n';
        return host::kExitInput;
    } catch (const hal::ModbusError& e) {
        std::cerr << "pathstream: device: " << e.what() << '\n';
        return host::kExitDevice;
    } catch (const hal::GpioError& e) {
        std::cerr << "pathstream: " << e.what() << '\n';
        return host::kExitDevice;
    } catch (const std::invalid_argument& e) {
        std::cerr << "pathstream: " << e.what() << '\n';
        return host::kExitUsage;
    } catch (const std::system_error& e) {
        std::cerr << "pathstream: " << e.what() << '\n';
        return host::kExitDevice;
    } catch (const std::runtime_error& e) {
        std::cerr << "pathstream: " << e.what() << '\n';
        return host::kExitOutput;
    } catch (const std::exception& e) {
        std::cerr << "pathstream: internal error: " << e.what() << '\n';
        return host::kExitInternal;
    } catch (...) {
        std::cerr << "pathstream: internal error: an exception of unknown type\n";
        return host::kExitInternal;
    }
}

int parse_and_run(CLI::App& app, int argc, char** argv, const std::function<int()>& run) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return host::kExitUsage;
    }
    try {
        return run();
    } catch (...) {
        return failure_exit(std::current_exception());
    }
}

}  // namespace pathstream::device_cli
