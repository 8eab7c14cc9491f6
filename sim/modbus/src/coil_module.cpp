#include "pathstream/sim/coil_module.hpp"

#include <modbus/modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <stdexcept>
#include <system_error>

namespace pathstream::sim {
namespace {

modbus_t* context(void* p) {
    return static_cast<modbus_t*>(p);
}
modbus_mapping_t* mapping(void* p) {
    return static_cast<modbus_mapping_t*>(p);
}

}  // namespace

CoilModule::CoilModule(std::uint32_t coils, std::uint16_t port) {
    if (coils < 1 || coils > 65536)
        throw std::invalid_argument("coil module: " + std::to_string(coils) +
                                    " coils is not in 1..65536");
    ctx_ = modbus_new_tcp("127.0.0.1", port);
    if (ctx_ == nullptr) throw std::system_error(errno, std::generic_category(), "modbus_new_tcp");
    mapping_ = modbus_mapping_new(static_cast<int>(coils), 0, 0, 0);
    if (mapping_ == nullptr) {
        modbus_free(context(ctx_));
        throw std::system_error(errno, std::generic_category(), "modbus_mapping_new");
    }
    listen_fd_ = modbus_tcp_listen(context(ctx_), 8);
    sockaddr_in bound{};
    socklen_t length = sizeof bound;
    if (listen_fd_ < 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &length) != 0) {
        const int err = errno;
        if (listen_fd_ >= 0) ::close(listen_fd_);
        modbus_mapping_free(mapping(mapping_));
        modbus_free(context(ctx_));
        throw std::system_error(err, std::generic_category(),
                                "coil module: listen on 127.0.0.1:" + std::to_string(port));
    }
    port_ = ntohs(bound.sin_port);
    thread_ = std::thread([this] { serve(); });
}

CoilModule::~CoilModule() {
    stop();
    modbus_mapping_free(mapping(mapping_));
    modbus_free(context(ctx_));
}

std::string CoilModule::url(int unit) const {
    return "modbus-tcp://127.0.0.1:" + std::to_string(port_) + "?unit=" + std::to_string(unit);
}

bool CoilModule::coil(std::uint16_t address) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    const modbus_mapping_t* m = mapping(mapping_);
    return address < m->nb_bits && m->tab_bits[address] != 0;
}

std::vector<CoilModule::Change> CoilModule::changes() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return changes_;
}

std::uint64_t CoilModule::write_requests() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return write_requests_;
}

std::uint64_t CoilModule::waiting_requests() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return waiting_;
}

void CoilModule::hold_answers(bool held) {
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        held_ = held;
    }
    answered_.notify_all();
}

bool CoilModule::wait_until(const std::function<bool(const CoilModule&)>& done,
                            std::chrono::milliseconds limit) const {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    for (;;) {
        if (done(*this)) return true;
        if (std::chrono::steady_clock::now() >= deadline) return false;
        std::unique_lock<std::mutex> lock(mutex_);
        answered_.wait_for(lock, std::chrono::milliseconds(10));
    }
}

void CoilModule::stop() {
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    answered_.notify_all();
    if (thread_.joinable()) thread_.join();
    if (listen_fd_ >= 0) ::close(listen_fd_);
    listen_fd_ = -1;
}

void CoilModule::serve() {
    std::vector<pollfd> fds;
    for (;;) {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            if (stopping_) break;
        }
        fds.assign(1, pollfd{listen_fd_, POLLIN, 0});
        for (const int c : clients_) fds.push_back(pollfd{c, POLLIN, 0});
        // A bounded wait: stop() is seen within 10 ms.
        if (::poll(fds.data(), fds.size(), 10) <= 0) continue;
        if ((fds[0].revents & POLLIN) != 0) {
            const int c = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
            if (c >= 0) clients_.push_back(c);
        }
        for (std::size_t k = 1; k < fds.size(); ++k) {
            if ((fds[k].revents & (POLLIN | POLLHUP | POLLERR)) != 0) answer(fds[k].fd);
        }
        clients_.erase(std::remove(clients_.begin(), clients_.end(), -1), clients_.end());
    }
    for (const int c : clients_) ::close(c);
    clients_.clear();
}

// One request from client `fd`: taken, held while hold_answers says so, then applied and
// answered by libmodbus under the lock, so that a client that has its answer and then asks
// coil() sees the change. A closed connection is closed here too.
void CoilModule::answer(int fd) {
    modbus_t* ctx = context(ctx_);
    modbus_set_socket(ctx, fd);
    std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
    const int length = modbus_receive(ctx, query);
    const auto drop = [this, fd] {
        ::close(fd);
        std::replace(clients_.begin(), clients_.end(), fd, -1);
    };
    if (length < 0) {
        drop();
        return;
    }
    if (length == 0) return;  // not for this unit (serial lines only)
    const std::uint8_t function = query[modbus_get_header_length(ctx)];
    const bool write =
        function == MODBUS_FC_WRITE_SINGLE_COIL || function == MODBUS_FC_WRITE_MULTIPLE_COILS;
    std::unique_lock<std::mutex> lock(mutex_);
    ++waiting_;
    answered_.notify_all();
    answered_.wait(lock, [this] { return !held_ || stopping_; });
    --waiting_;
    if (stopping_) {  // switched off with the request unanswered
        lock.unlock();
        drop();
        return;
    }
    modbus_mapping_t* m = mapping(mapping_);
    const std::vector<std::uint8_t> before(m->tab_bits, m->tab_bits + m->nb_bits);
    if (modbus_reply(ctx, query, length, m) < 0) {
        lock.unlock();
        drop();
        return;
    }
    if (write) ++write_requests_;
    for (int k = 0; k < m->nb_bits; ++k) {
        const std::size_t i = static_cast<std::size_t>(k);
        if ((before[i] != 0) != (m->tab_bits[i] != 0)) {
            changes_.push_back(
                Change{static_cast<std::uint16_t>(k), m->tab_bits[i] != 0, write_requests_});
        }
    }
    lock.unlock();
    answered_.notify_all();
}

}  // namespace pathstream::sim
