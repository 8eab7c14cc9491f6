// Interoperability of the simulated device's register map with an independent master: Debian's
// mbpoll (libmodbus-based) reads the status block and drives the command register over TCP and
// RTU (a pty), as a user checking a device by hand would. mbpoll numbers references from 1.
#include <unistd.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pathstream/device/modbus_map.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"

using namespace pathstream;
using Catch::Matchers::Contains;

namespace {

namespace mb = device::modbus;
namespace st = device::modbus::status;

std::string find_mbpoll() {
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        const std::string candidate = dir + "/mbpoll";
        if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    return "";
}

// Runs mbpoll with `args` (under coreutils' timeout: it never hangs the test); stdout+stderr.
std::string mbpoll(const std::string& program, const std::string& args) {
    const std::string command = "timeout 10 " + program + " " + args + " 2>&1";
    FILE* p = ::popen(command.c_str(), "r");
    REQUIRE(p != nullptr);
    std::string out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
    ::pclose(p);
    return out;
}

// mbpoll's "[ref]: value" lines as ref -> value.
std::map<int, long> values(const std::string& out) {
    std::map<int, long> v;
    static const std::regex line(R"(^\[(\d+)\]:\s*(-?\d+)\s*$)");
    std::stringstream in(out);
    std::string l;
    while (std::getline(in, l)) {
        std::smatch m;
        if (std::regex_match(l, m, line)) v[std::stoi(m[1])] = std::stol(m[2]);
    }
    return v;
}

// Serves the device and ticks it (real time) until destroyed.
struct DeviceThread {
    std::unique_ptr<linux_device::ModbusMotionDevice> device;
    hal::ModbusServer* server = nullptr;
    std::atomic<bool> stop{false};
    std::thread thread;
    void run() {
        thread = std::thread([this] {
            linux_device::run_device_loop(
                *device, [&](std::chrono::microseconds w) { server->poll_once(w); }, {}, stop);
        });
    }
    void halt() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
    ~DeviceThread() { halt(); }
};

// Declared after the server it guards: joins the device thread before the server goes away,
// on every exit from the scope (a failed REQUIRE included).
struct HaltBeforeServer {
    DeviceThread& thread;
    ~HaltBeforeServer() { thread.halt(); }
};

// The configuration block for 2 axes at 1 kHz, 250,000 LSB/s and 3,000,000 LSB/s^2 per axis, as
// mbpoll write values (registers kConfig + 0 .. + 17).
std::string config_values() {
    std::ostringstream v;
    v << "0 1000 2 0 0 0 0 0 0 0";
    for (int a = 0; a < 2; ++a)
        v << ' ' << (250000 >> 16) << ' ' << (250000 & 0xFFFF) << ' ' << (3000000 >> 16) << ' '
          << (3000000 & 0xFFFF);
    v << " 0 0 0 0 0 0 0 0";  // travel of both axes: 0, 0 = no soft limits
    v << " 0 0 0 0";          // max jerk of both axes: 0 = no jerk limit
    return v.str();
}

// Reads the state register with mbpoll until it equals `want` (the device applies commands on
// its next tick) or 2 s pass; returns the last value read.
long wait_state(const std::string& program, const std::string& link, long want) {
    long state = -1;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    do {
        const auto v = values(
            mbpoll(program, link + " -r " + std::to_string(st::kState + 1) + " -c 1 -t 3 -1"));
        state = v.count(st::kState + 1) != 0 ? v.at(st::kState + 1) : -1;
        if (state == want) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    } while (std::chrono::steady_clock::now() < deadline);
    return state;
}

// What both transports must show: identity, capacity, the start positions (32-bit, high word
// first: mbpoll's -B), commands refused and accepted, state changes.
void check_device(const std::string& program, const std::string& link) {
    // Status block, 16-bit registers 1..12 (PDU addresses 0..11).
    const std::string out = mbpoll(program, link + " -r 1 -c 12 -t 3 -1");
    INFO("mbpoll output:\n" << out);
    const auto v = values(out);
    REQUIRE(v.size() == 12);
    CHECK(v.at(st::kMagic + 1) == 0x5053);
    CHECK(v.at(st::kVersion + 1) == mb::kProtocolVersion);
    CHECK(v.at(st::kState + 1) == 0);  // idle
    CHECK(v.at(st::kFaultCode + 1) == 0);
    CHECK(v.at(st::kFreeSlots + 1) == linux_device::kModbusDeviceCapacity);
    CHECK(v.at(st::kCapacity + 1) == linux_device::kModbusDeviceCapacity);

    // Positions as 32-bit integers, big-endian word order: the start the device was made with.
    const std::string pos = mbpoll(
        program, link + " -r " + std::to_string(st::kPositions + 1) + " -c 2 -t 3:int -B -1");
    INFO("mbpoll output:\n" << pos);
    const auto p = values(pos);
    REQUIRE(p.size() == 2);
    CHECK(p.at(st::kPositions + 1) == 1234);
    CHECK(p.at(st::kPositions + 3) == -70000);
    const auto axes =
        values(mbpoll(program, link + " -r " + std::to_string(st::kAxes + 1) + " -c 1 -t 3 -1"));
    CHECK(axes.at(st::kAxes + 1) == 2);

    // FC6 start while unconfigured: refused with server device failure, state unchanged.
    const std::string refused =
        mbpoll(program, link + " -r " + std::to_string(mb::kCommand + 1) + " -t 4 -1 1");
    INFO("mbpoll output:\n" << refused);
    CHECK_THAT(refused, Contains("failure"));
    CHECK(wait_state(program, link, 0) == 0);

    // FC16 configuration, read back with FC3; the configured flag is set.
    const std::string written = mbpoll(
        program, link + " -r " + std::to_string(mb::kConfig + 1) + " -t 4 -1 " + config_values());
    INFO("mbpoll output:\n" << written);
    CHECK_THAT(written, Contains("Written 30 references"));
    const auto hz = values(
        mbpoll(program, link + " -r " + std::to_string(mb::kConfig + 1) + " -c 2 -t 4:int -B -1"));
    CHECK(hz.at(mb::kConfig + 1) == 1000);
    const auto flags =
        values(mbpoll(program, link + " -r " + std::to_string(st::kFlags + 1) + " -c 1 -t 3 -1"));
    CHECK(flags.at(st::kFlags + 1) == 1);

    // FC6 start with nothing queued: refused (nothing would move), the device stays idle and
    // register 30 says why (17, nothing queued); FC6 stop while idle: accepted (it drops
    // whatever is queued, here nothing).
    CHECK_THAT(mbpoll(program, link + " -r " + std::to_string(mb::kCommand + 1) + " -t 4 -1 1"),
               Contains("failure"));
    CHECK(wait_state(program, link, 0) == 0);
    const auto why = values(
        mbpoll(program, link + " -r " + std::to_string(st::kLastRefusal + 1) + " -c 1 -t 3 -1"));
    CHECK(why.at(st::kLastRefusal + 1) == static_cast<long>(Status::kNothingToResume));
    CHECK_THAT(mbpoll(program, link + " -r " + std::to_string(mb::kCommand + 1) + " -t 4 -1 4"),
               Contains("Written 1 references"));
    CHECK(wait_state(program, link, 0) == 0);
    // The command register reads back the last command accepted.
    const auto cmd =
        values(mbpoll(program, link + " -r " + std::to_string(mb::kCommand + 1) + " -c 1 -t 4 -1"));
    CHECK(cmd.at(mb::kCommand + 1) == 4);
}

}  // namespace

TEST_CASE(
    "mbpoll reads the simulated device's status block and drives its commands over TCP and RTU",
    "[modbus][mbpoll][threads]") {
    const std::string program = find_mbpoll();
    if (program.empty()) {
        WARN(
            "mbpoll not found on PATH: the interoperability test is skipped (scripts/setup.sh "
            "installs it)");
        return;
    }
    SECTION("TCP, ephemeral port") {
        DeviceThread dt;
        dt.device = linux_device::ModbusMotionDevice::create({1234, -70000});
        hal::ModbusServer server =
            hal::ModbusServer::tcp(dt.device->handler(), {"127.0.0.1", 0, 4});
        dt.server = &server;
        const HaltBeforeServer guard{dt};
        dt.run();
        check_device(program,
                     "-m tcp -a 1 -o 2 -p " + std::to_string(server.port()) + " 127.0.0.1");
    }
    SECTION("RTU on a pty, 115200 8N1") {
        DeviceThread dt;
        dt.device = linux_device::ModbusMotionDevice::create({1234, -70000});
        hal::ModbusServer server = hal::ModbusServer::rtu_pty(dt.device->handler());
        dt.server = &server;
        const HaltBeforeServer guard{dt};
        dt.run();
        check_device(program, "-m rtu -b 115200 -P none -a 1 -o 2 " + server.client_device());
    }
}
