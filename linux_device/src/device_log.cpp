#include "pathstream/linux_device/device_log.hpp"

#include <chrono>
#include <iostream>

namespace pathstream::linux_device {

void DeviceLog::operator()(const char* event, const std::string& text,
                           const host::EventJson& fields) const {
    const std::string time = host::iso8601_utc(std::chrono::system_clock::now());
    if (!json_) {
        std::cout << time << " pathstream device: " << text << std::endl;
        return;
    }
    host::EventJson line;
    line["time"] = time;
    line["event"] = event;
    for (auto it = fields.begin(); it != fields.end(); ++it) line[it.key()] = it.value();
    line["message"] = text;
    std::cout << line.dump(-1, ' ', false, host::EventJson::error_handler_t::replace) << std::endl;
}

}  // namespace pathstream::linux_device
