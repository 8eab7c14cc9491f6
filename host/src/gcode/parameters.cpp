// Parameter storage and call scopes (docs/formats-gcode.md, "Parameters").
#include "parameters.hpp"

#include <stdexcept>

namespace pathstream::host::gcode {

std::string parameter_text(const ParameterRef& ref) {
    return ref.name.empty() ? "#" + std::to_string(ref.number) : "#<" + ref.name + ">";
}

std::optional<double> Parameters::get(const ParameterRef& ref) const {
    if (ref.name.empty()) return numbered_.at(static_cast<std::size_t>(ref.number));
    const auto& scope = ref.name.front() == '_' ? globals_ : locals_.back();
    const auto found = scope.find(ref.name);
    if (found == scope.end()) return std::nullopt;
    return found->second;
}

void Parameters::set(const ParameterRef& ref, double value) {
    if (ref.name.empty()) {
        numbered_.at(static_cast<std::size_t>(ref.number)) = value;
    } else if (ref.name.front() == '_') {
        globals_[ref.name] = value;
    } else {
        locals_.back()[ref.name] = value;
    }
}

bool Parameters::exists(const std::string& name) const {
    const auto& scope = !name.empty() && name.front() == '_' ? globals_ : locals_.back();
    return scope.count(name) != 0;
}

void Parameters::enter_call(const std::vector<double>& arguments) {
    if (arguments.size() > kCallArguments) throw std::logic_error("enter_call: > 30 arguments");
    std::array<double, kCallArguments> saved{};
    for (std::size_t k = 0; k < kCallArguments; ++k) saved[k] = numbered_[k + 1];
    saved_arguments_.push_back(saved);
    // As LinuxCNC's execute_call: all 30 are set, those after the last argument to 0.
    for (std::size_t k = 0; k < kCallArguments; ++k) {
        numbered_[k + 1] = k < arguments.size() ? arguments[k] : 0.0;
    }
    locals_.emplace_back();
}

void Parameters::leave_call() {
    if (saved_arguments_.empty()) throw std::logic_error("leave_call: not in a call");
    const auto& saved = saved_arguments_.back();
    for (std::size_t k = 0; k < kCallArguments; ++k) numbered_[k + 1] = saved[k];
    saved_arguments_.pop_back();
    locals_.pop_back();
}

}  // namespace pathstream::host::gcode
