// RS274NGC parameters as LinuxCNC keeps them: numbered #1..#5602, named locals #<name> (one
// scope per subroutine call) and named globals #<_name>.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pathstream::host::gcode {

/// A parameter an assignment or a read names.
struct ParameterRef {
    long number = 0;   ///< 1..kMaxParameter when `name` is empty
    std::string name;  ///< lower case, blanks removed; '_' first: global
};

/// "#12" or "#<name>", for messages.
std::string parameter_text(const ParameterRef& ref);

class Parameters {
public:
    static constexpr long kMaxParameter = 5602;        ///< LinuxCNC's RS274NGC_MAX_PARAMETERS
    static constexpr std::size_t kCallArguments = 30;  ///< #1..#30 are a call's arguments

    /// The value of a numbered parameter (0 until set); nullopt for an undefined named one.
    std::optional<double> get(const ParameterRef& ref) const;
    /// Sets a parameter; a named one is created in the current call's scope (or globally).
    void set(const ParameterRef& ref, double value);
    /// Whether a named parameter is defined (EXISTS).
    bool exists(const std::string& name) const;

    /// Enters a subroutine: saves #1..#30, sets #1..#n to `arguments` (n <= 30) and the rest
    /// of #1..#30 to 0, and opens a fresh local scope.
    void enter_call(const std::vector<double>& arguments);
    /// Leaves the innermost call: restores #1..#30 and drops its locals.
    void leave_call();

private:
    std::vector<double> numbered_ = std::vector<double>(kMaxParameter + 1, 0.0);
    std::map<std::string, double> globals_;
    std::vector<std::map<std::string, double>> locals_ =
        std::vector<std::map<std::string, double>>(1);
    std::vector<std::array<double, kCallArguments>> saved_arguments_;
};

}  // namespace pathstream::host::gcode
