// Self-test of the real-kernel test VM (docs/vm.md): runs inside Debian's kernel under qemu and
// proves that SocketCAN (vcan) and gpio-sim behave like real hardware would for pathstream's
// backends. Every wait is bounded; every failure prints one line and returns non-zero.
//
//   vm_selftest can IFACE                  two raw sockets: filters, std/ext ids, no own echo
//   vm_selftest can-recv IFACE ID MS [READY_FILE]
//                                          wait MS for one frame with hex ID, print it as
//                                          candump -L prints data ("123#DEADBEEF")
//   vm_selftest gpio CHIP SIM_SYSFS_DIR    libgpiod 1.6 against gpio-sim: output read back
//                                          through sim_gpioN/value, edge events from
//                                          sim_gpioN/pull, bias flags, line names
#include <gpiod.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>

namespace {

int fail(const char* what) {
    std::fprintf(stderr, "vm_selftest: FAIL: %s (errno %d: %s)\n", what, errno,
                 std::strerror(errno));
    return 1;
}

int failf(const std::string& what) {
    std::fprintf(stderr, "vm_selftest: FAIL: %s\n", what.c_str());
    return 1;
}

// ---------------------------------------------------------------------------------------------
// SocketCAN
class CanSocket {
public:
    CanSocket() : fd_(::socket(PF_CAN, SOCK_RAW, CAN_RAW)) {}
    ~CanSocket() {
        if (fd_ >= 0) ::close(fd_);
    }
    CanSocket(const CanSocket&) = delete;
    CanSocket& operator=(const CanSocket&) = delete;
    int fd() const { return fd_; }
    bool bind_to(const char* iface) {
        if (fd_ < 0) return false;
        ifreq ifr{};
        std::snprintf(ifr.ifr_name, sizeof ifr.ifr_name, "%s", iface);
        if (::ioctl(fd_, SIOCGIFINDEX, &ifr) < 0) return false;
        sockaddr_can addr{};
        addr.can_family = AF_CAN;
        addr.can_ifindex = ifr.ifr_ifindex;
        return ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    }
    // 1: a frame, 0: nothing within timeout_ms, -1: error.
    int receive(can_frame& frame, int timeout_ms) const {
        pollfd p{fd_, POLLIN, 0};
        const int n = ::poll(&p, 1, timeout_ms);
        if (n <= 0) return n;
        const ssize_t got = ::read(fd_, &frame, sizeof frame);
        return got == static_cast<ssize_t>(sizeof frame) ? 1 : -1;
    }
    bool send(const can_frame& frame) const {
        return ::write(fd_, &frame, sizeof frame) == static_cast<ssize_t>(sizeof frame);
    }

private:
    int fd_;
};

can_frame make_frame(canid_t id, std::string_view bytes) {
    can_frame f{};
    f.can_id = id;
    f.len = static_cast<__u8>(bytes.size());
    std::memcpy(f.data, bytes.data(), bytes.size());
    return f;
}

std::string format_frame(const can_frame& f) {
    char buf[64];
    const bool ext = (f.can_id & CAN_EFF_FLAG) != 0;
    int n = std::snprintf(buf, sizeof buf, ext ? "%08X#" : "%03X#",
                          f.can_id & (ext ? CAN_EFF_MASK : CAN_SFF_MASK));
    for (int i = 0; i < f.len && n < 60; ++i) n += std::snprintf(buf + n, 4, "%02X", f.data[i]);
    return buf;
}

bool same(const can_frame& a, const can_frame& b) {
    return a.can_id == b.can_id && a.len == b.len && std::memcmp(a.data, b.data, a.len) == 0;
}

int test_can(const char* iface) {
    CanSocket tx, rx;
    if (tx.fd() < 0 || rx.fd() < 0) return fail("socket(PF_CAN, SOCK_RAW, CAN_RAW)");
    // rx accepts standard id 0x123 and extended id 0x1ABCDEF only.
    const can_filter filters[] = {
        {0x123, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG},
        {0x1ABCDEF | CAN_EFF_FLAG, CAN_EFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG},
    };
    if (::setsockopt(rx.fd(), SOL_CAN_RAW, CAN_RAW_FILTER, filters, sizeof filters) != 0)
        return fail("setsockopt(CAN_RAW_FILTER)");
    if (!tx.bind_to(iface) || !rx.bind_to(iface)) return fail("bind to the CAN interface");

    const can_frame wanted1 = make_frame(0x123, "\xDE\xAD\xBE\xEF");
    const can_frame filtered = make_frame(0x124, "\x01");
    const can_frame wanted2 = make_frame(0x1ABCDEF | CAN_EFF_FLAG,
                                         std::string_view("\x00\x01\x02\x03\x04\x05\x06\x07", 8));
    for (const can_frame* f : {&wanted1, &filtered, &wanted2})
        if (!tx.send(*f)) return fail("write(CAN frame)");

    for (const can_frame* want : {&wanted1, &wanted2}) {
        can_frame got{};
        const int r = rx.receive(got, 3000);
        if (r < 0) return fail("read(CAN frame)");
        if (r == 0) return failf("no frame " + format_frame(*want) + " within 3 s");
        if (!same(got, *want))
            return failf("received " + format_frame(got) + ", expected " + format_frame(*want));
        std::printf("vm_selftest: can: received %s\n", format_frame(got).c_str());
    }
    can_frame extra{};
    if (rx.receive(extra, 200) != 0)
        return failf("the filter let " + format_frame(extra) + " through");
    // Loopback reaches other sockets, not the sender (CAN_RAW_RECV_OWN_MSGS is off).
    if (tx.receive(extra, 200) != 0) return failf("the sender received its own frame");
    std::printf("vm_selftest: can: OK (filters, standard and extended ids, no own echo)\n");
    return 0;
}

int test_can_recv(const char* iface, const char* id_hex, int timeout_ms, const char* ready_file) {
    const unsigned long id = std::strtoul(id_hex, nullptr, 16);
    CanSocket rx;
    if (rx.fd() < 0) return fail("socket(PF_CAN, SOCK_RAW, CAN_RAW)");
    if (!rx.bind_to(iface)) return fail("bind to the CAN interface");
    if (ready_file != nullptr) std::ofstream(ready_file) << "ready\n";
    can_frame got{};
    for (;;) {
        const int r = rx.receive(got, timeout_ms);
        if (r < 0) return fail("read(CAN frame)");
        if (r == 0) return failf("no frame with id " + std::string(id_hex) + " in time");
        if ((got.can_id & CAN_EFF_MASK) == id) break;
    }
    std::printf("%s\n", format_frame(got).c_str());
    return 0;
}

// ---------------------------------------------------------------------------------------------
// GPIO (libgpiod 1.6 C API) against gpio-sim
std::string read_attr(const std::string& path) {
    std::ifstream in(path);
    std::string s;
    std::getline(in, s);
    return s;
}

bool write_attr(const std::string& path, const char* value) {
    std::ofstream out(path);
    out << value;
    out.flush();
    return static_cast<bool>(out);
}

struct Chip {
    gpiod_chip* chip;
    explicit Chip(const char* path) : chip(gpiod_chip_open(path)) {}
    ~Chip() {
        if (chip != nullptr) gpiod_chip_close(chip);
    }
    Chip(const Chip&) = delete;
    Chip& operator=(const Chip&) = delete;
};

// Reads one edge event within timeout_ms; returns its type or 0 for none, -1 for an error.
int next_event(gpiod_line* line, long timeout_ms) {
    timespec ts{timeout_ms / 1000, (timeout_ms % 1000) * 1000000L};
    const int r = gpiod_line_event_wait(line, &ts);
    if (r <= 0) return r;
    gpiod_line_event ev{};
    if (gpiod_line_event_read(line, &ev) != 0) return -1;
    return ev.event_type;
}

int test_gpio(const char* chip_path, const std::string& sim_dir) {
    Chip c(chip_path);
    if (c.chip == nullptr) return fail("gpiod_chip_open");
    std::printf("vm_selftest: gpio: chip %s label \"%s\", %u lines\n", gpiod_chip_name(c.chip),
                gpiod_chip_label(c.chip), gpiod_chip_num_lines(c.chip));
    if (gpiod_chip_num_lines(c.chip) != 16) return failf("expected 16 lines");

    // 1. Output: value set through libgpiod, read back through the simulator's sysfs.
    gpiod_line* pen = gpiod_chip_find_line(c.chip, "pen-lift");
    if (pen == nullptr) return fail("gpiod_chip_find_line(\"pen-lift\")");
    const unsigned pen_off = gpiod_line_offset(pen);
    const std::string pen_value = sim_dir + "/sim_gpio" + std::to_string(pen_off) + "/value";
    if (gpiod_line_request_output(pen, "vm_selftest", 0) != 0)
        return fail("request pen-lift output");
    for (int v : {0, 1, 0, 1}) {
        if (gpiod_line_set_value(pen, v) != 0) return fail("gpiod_line_set_value");
        const std::string seen = read_attr(pen_value);
        if (seen != std::to_string(v))
            return failf("pen-lift set to " + std::to_string(v) + ", " + pen_value + " reads '" +
                         seen + "'");
    }
    gpiod_line_release(pen);
    std::printf("vm_selftest: gpio: output line %u read back through %s\n", pen_off,
                pen_value.c_str());

    // 2. Input with edge events: the simulator's pull attribute plays the outside world.
    gpiod_line* estop = gpiod_chip_find_line(c.chip, "estop");
    if (estop == nullptr) return fail("gpiod_chip_find_line(\"estop\")");
    const std::string estop_pull =
        sim_dir + "/sim_gpio" + std::to_string(gpiod_line_offset(estop)) + "/pull";
    if (!write_attr(estop_pull, "pull-down")) return failf("cannot write " + estop_pull);
    if (gpiod_line_request_both_edges_events(estop, "vm_selftest") != 0)
        return fail("request estop edge events");
    if (gpiod_line_get_value(estop) != 0) return failf("estop should read 0 when pulled down");
    struct Step {
        const char* pull;
        int event;
        int value;
    };
    for (const Step& s : {Step{"pull-up", GPIOD_LINE_EVENT_RISING_EDGE, 1},
                          Step{"pull-down", GPIOD_LINE_EVENT_FALLING_EDGE, 0},
                          Step{"pull-up", GPIOD_LINE_EVENT_RISING_EDGE, 1}}) {
        if (!write_attr(estop_pull, s.pull)) return failf("cannot write " + estop_pull);
        const int ev = next_event(estop, 3000);
        if (ev < 0) return fail("gpiod_line_event_wait/read");
        if (ev == 0) return failf(std::string("no edge event within 3 s after ") + s.pull);
        if (ev != s.event) return failf(std::string("wrong edge after ") + s.pull);
        if (gpiod_line_get_value(estop) != s.value)
            return failf(std::string("wrong value after ") + s.pull);
    }
    if (next_event(estop, 200) != 0) return failf("spurious edge event on estop");
    // The event fd is a plain pollable fd: what an event loop would use.
    const int efd = gpiod_line_event_get_fd(estop);
    if (!write_attr(estop_pull, "pull-down")) return failf("cannot write " + estop_pull);
    pollfd p{efd, POLLIN, 0};
    if (::poll(&p, 1, 3000) != 1) return failf("poll() on the event fd saw no edge");
    if (next_event(estop, 0) != GPIOD_LINE_EVENT_FALLING_EDGE) return failf("poll: wrong edge");
    gpiod_line_release(estop);
    std::printf("vm_selftest: gpio: rising/falling edge events on estop via the sim's pull\n");

    // 3. Bias flags reach the simulated line (gpio-sim implements set_config).
    gpiod_line* spare = gpiod_chip_get_line(c.chip, 7);
    if (spare == nullptr) return fail("gpiod_chip_get_line(7)");
    for (int up : {1, 0}) {
        gpiod_line_request_config cfg{
            "vm_selftest", GPIOD_LINE_REQUEST_DIRECTION_INPUT,
            up ? GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP : GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN};
        if (gpiod_line_request(spare, &cfg, 0) != 0) return fail("request line 7 with a bias");
        if (gpiod_line_get_value(spare) != up) return failf("bias did not reach line 7");
        gpiod_line_release(spare);
    }
    std::printf("vm_selftest: gpio: OK (output read-back, edge events, bias)\n");
    return 0;
}

int usage() {
    std::fprintf(stderr,
                 "usage: vm_selftest can IFACE\n"
                 "       vm_selftest can-recv IFACE HEX_ID TIMEOUT_MS [READY_FILE]\n"
                 "       vm_selftest gpio CHIP_PATH SIM_SYSFS_DIR\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) return usage();
    const std::string_view mode = argv[1];
    if (mode == "can" && argc == 3) return test_can(argv[2]);
    if (mode == "can-recv" && (argc == 5 || argc == 6))
        return test_can_recv(argv[2], argv[3], std::atoi(argv[4]), argc == 6 ? argv[5] : nullptr);
    if (mode == "gpio" && argc == 4) return test_gpio(argv[2], argv[3]);
    return usage();
}
