// The Modbus transport over TCP on loopback (ephemeral ports): round trips of every function,
// exception answers that change nothing, dropped connections, dead peers, byte counters.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <numeric>
#include <optional>
#include <vector>

#include "pathstream/hal/modbus_adu.hpp"
#include "pathstream/hal/modbus_client.hpp"
#include "register_array.hpp"

using namespace pathstream::hal;
using pathstream::test::RegisterArray;
using pathstream::test::ServingThread;
using Kind = ModbusError::Kind;
using std::chrono::milliseconds;

namespace {

std::string url_for(const ModbusServer& server, int unit = 1) {
    return "modbus-tcp://127.0.0.1:" + std::to_string(server.port()) +
           "?unit=" + std::to_string(unit);
}

ModbusClientOptions fast(int attempts = 1) {
    ModbusClientOptions o;
    o.response_timeout = milliseconds(200);
    o.byte_timeout = milliseconds(50);
    o.attempts = attempts;
    return o;
}

// Runs `call` and returns the ModbusError it throws (fails the test if it throws none).
template <class Call>
ModbusError error_of(Call call) {
    try {
        call();
    } catch (const ModbusError& e) {
        return e;
    }
    FAIL("no ModbusError thrown");
    return ModbusError(Kind::kBadFrame, "unreachable");
}

// A raw loopback socket, to speak Modbus bytes that no well-behaved client would send.
int raw_connect(std::uint16_t port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    REQUIRE(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0);
    timeval tv{2, 0};  // never hang the test on a missing answer
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    return fd;
}

}  // namespace

TEST_CASE("TCP: FC3, FC4, FC6, FC16 and FC23 round trips", "[modbus][tcp][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    REQUIRE(server.port() != 0);
    ServingThread serving(server);
    ModbusClient client(url_for(server), fast());

    std::vector<std::uint16_t> in(125);
    client.read_input_registers(10, in);
    for (std::size_t i = 0; i < in.size(); ++i) CHECK(in[i] == 3 * (10 + i) + 1);

    std::vector<std::uint16_t> block(123);
    std::iota(block.begin(), block.end(), std::uint16_t{500});
    client.write_registers(100, block);
    client.write_register(99, 0xBEEF);
    std::vector<std::uint16_t> back(125);
    client.read_holding_registers(99, back);
    CHECK(back[0] == 0xBEEF);
    for (std::size_t i = 0; i < block.size(); ++i) CHECK(back[1 + i] == block[i]);
    CHECK(back[124] == 0);

    // FC23: written first, read after: the read sees the new values where the ranges overlap.
    const std::vector<std::uint16_t> w = {1, 2, 3, 4};
    std::vector<std::uint16_t> r(6);
    client.write_read_registers(300, w, 298, r);
    CHECK(r == std::vector<std::uint16_t>{0, 0, 1, 2, 3, 4});

    serving.stop();
    CHECK(registers.holding[99] == 0xBEEF);
    CHECK(registers.holding[303] == 4);
    CHECK(server.counters().requests == 5);
    CHECK(server.counters().exceptions == 0);
    CHECK(client.counters().transactions == 5);
    CHECK(client.counters().attempts == 5);
}

TEST_CASE("TCP: FC23 answers with what the handler reads, not with what was written",
          "[modbus][tcp][threads]") {
    // A register map may transform writes (here: it stores the complement). modbus_reply
    // would copy the written values into the overlapping part of the answer; the server
    // must answer with the handler's read.
    struct Complementing : RegisterArray {
        ModbusException write_holding_registers(std::uint16_t address, std::uint16_t count,
                                                const std::uint16_t* values) override {
            for (std::uint16_t i = 0; i < count; ++i)
                holding[address + i] = static_cast<std::uint16_t>(~values[i]);
            return ModbusException::kNone;
        }
    } registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    ServingThread serving(server);
    ModbusClient client(url_for(server), fast());
    const std::vector<std::uint16_t> w = {0x0001, 0x0002, 0x0003};
    std::vector<std::uint16_t> r(4);
    client.write_read_registers(10, w, 11, r);
    CHECK(r == std::vector<std::uint16_t>{0xFFFD, 0xFFFC, 0, 0});
}

TEST_CASE("TCP: exception responses carry the code and change nothing", "[modbus][tcp][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    ServingThread serving(server);
    ModbusClient client(url_for(server), fast(3));  // exceptions are never retried
    const std::vector<std::uint16_t> before = {7, 8, 9, 10};
    client.write_registers(890, before);

    std::vector<std::uint16_t> two(2);
    ModbusError e = error_of([&] { client.read_holding_registers(999, two); });
    CHECK(e.kind() == Kind::kExceptionResponse);
    CHECK(e.exception_code() == 2);
    CHECK(std::string(e.what()).find("exception response 2 (illegal data address)") !=
          std::string::npos);

    // Straddles the read-only block: refused as a whole, 890..899 keep their values.
    const std::vector<std::uint16_t> straddle(20, 1);
    e = error_of([&] { client.write_registers(890, straddle); });
    CHECK(e.exception_code() == 2);
    // One refused value refuses the whole block.
    const std::vector<std::uint16_t> poisoned = {11, 12, RegisterArray::kRefusedValue, 14};
    e = error_of([&] { client.write_registers(890, poisoned); });
    CHECK(e.exception_code() == 3);
    e = error_of([&] { client.write_register(891, RegisterArray::kRefusedValue); });
    CHECK(e.exception_code() == 3);
    // FC23 whose write is refused: nothing written, nothing read.
    std::vector<std::uint16_t> out(4, 0x5555);
    e = error_of([&] { client.write_read_registers(890, poisoned, 890, out); });
    CHECK(e.exception_code() == 3);
    CHECK(out == std::vector<std::uint16_t>(4, 0x5555));
    // Input registers past the array: the handler refuses.
    ModbusError past = error_of([&] { client.read_input_registers(1000, two); });
    CHECK(past.exception_code() == 2);

    std::vector<std::uint16_t> now(4);
    client.read_holding_registers(890, now);
    CHECK(now == before);
    CHECK(client.counters().exception_responses == 6);
    CHECK(client.counters().retries == 0);
    serving.stop();
    CHECK(registers.writes_applied == 1);
    CHECK(server.counters().exceptions == 6);
}

TEST_CASE("TCP: unsupported and malformed requests get exceptions, the stream stays in step",
          "[modbus][tcp][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    ServingThread serving(server);
    const int fd = raw_connect(server.port());
    std::uint8_t reply[32];

    // FC1 (read coils): transaction 0x1234, unit 9 -> illegal function, ids echoed.
    const std::uint8_t fc1[] = {0x12, 0x34, 0, 0, 0, 6, 9, 0x01, 0, 0, 0, 8};
    REQUIRE(::send(fd, fc1, sizeof fc1, 0) == sizeof fc1);
    REQUIRE(::recv(fd, reply, sizeof reply, 0) == 9);
    CHECK(std::vector<std::uint8_t>(reply, reply + 9) ==
          std::vector<std::uint8_t>{0x12, 0x34, 0, 0, 0, 3, 9, 0x81, 0x01});

    // FC3 asking for 126 registers -> illegal data value (quantity before address).
    const std::uint8_t fc3[] = {0, 2, 0, 0, 0, 6, 1, 0x03, 0xFF, 0xFF, 0, 126};
    REQUIRE(::send(fd, fc3, sizeof fc3, 0) == sizeof fc3);
    REQUIRE(::recv(fd, reply, sizeof reply, 0) == 9);
    CHECK(reply[7] == 0x83);
    CHECK(reply[8] == 0x03);

    // FC16 whose byte count disagrees with its count -> illegal data value.
    const std::uint8_t fc16[] = {0, 3, 0, 0, 0, 9, 1, 0x10, 0, 0, 0, 2, 2, 0xAB, 0xCD};
    REQUIRE(::send(fd, fc16, sizeof fc16, 0) == sizeof fc16);
    REQUIRE(::recv(fd, reply, sizeof reply, 0) == 9);
    CHECK(reply[7] == 0x90);
    CHECK(reply[8] == 0x03);

    // Still in step: a good FC4 on the same connection.
    const std::uint8_t fc4[] = {0, 4, 0, 0, 0, 6, 1, 0x04, 0, 5, 0, 1};
    REQUIRE(::send(fd, fc4, sizeof fc4, 0) == sizeof fc4);
    REQUIRE(::recv(fd, reply, sizeof reply, 0) == 11);
    CHECK(reply[7] == 0x04);
    CHECK(reply[8] == 2);
    CHECK((reply[9] << 8 | reply[10]) == 16);
    ::close(fd);
    serving.stop();
    CHECK(registers.writes_applied == 0);
}

TEST_CASE("TCP: a half-sent request or a vanished client never stops the server",
          "[modbus][tcp][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    ServingThread serving(server);

    int fd = raw_connect(server.port());
    const std::uint8_t half[] = {0, 1, 0, 0, 0, 6, 1};  // MBAP only, then gone
    REQUIRE(::send(fd, half, sizeof half, 0) == sizeof half);
    ::close(fd);
    fd = raw_connect(server.port());  // connects and leaves without a word
    ::close(fd);

    ModbusClient client(url_for(server), fast());
    std::vector<std::uint16_t> v(3);
    client.read_input_registers(0, v);
    CHECK(v == std::vector<std::uint16_t>{1, 4, 7});
    CHECK(pathstream::test::eventually([&] { return server.counters().connections_closed >= 2; }));
}

TEST_CASE("TCP: a connection dropped mid-session, reconnect() resumes", "[modbus][tcp][threads]") {
    RegisterArray registers;
    ModbusTcpEndpoint endpoint;
    endpoint.max_clients = 1;  // a second connection evicts the first: a real mid-session drop
    ModbusServer server = ModbusServer::tcp(registers, endpoint);
    ServingThread serving(server);

    ModbusClient first(url_for(server), fast());
    const std::vector<std::uint16_t> a = {1, 2, 3};
    first.write_registers(0, a);
    ModbusClient second(url_for(server), fast());
    const std::vector<std::uint16_t> b = {4, 5, 6};
    second.write_registers(3, b);  // served after the eviction of `first`

    std::vector<std::uint16_t> v(6);
    const ModbusError lost = error_of([&] { first.read_holding_registers(0, v); });
    CHECK(lost.kind() == Kind::kConnectionLost);
    CHECK_FALSE(first.connected());  // a failed TCP transaction leaves the link closed

    first.reconnect();
    CHECK(first.connected());
    first.read_holding_registers(0, v);
    CHECK(v == std::vector<std::uint16_t>{1, 2, 3, 4, 5, 6});
    CHECK(first.counters().reconnects == 1);
    CHECK(first.counters().connection_losses == 1);
}

TEST_CASE("TCP: after a server restart the client connects again", "[modbus][tcp][threads]") {
    RegisterArray registers;
    std::optional<ModbusServer> server = ModbusServer::tcp(registers, {});
    const std::uint16_t port = server->port();
    ModbusClient client("modbus-tcp://127.0.0.1:" + std::to_string(port), fast(1));
    {
        ServingThread serving(*server);
        client.write_register(5, 55);
    }
    server.reset();  // the server goes away: the connection is closed under the client

    std::vector<std::uint16_t> v(1);
    CHECK(error_of([&] { client.read_holding_registers(5, v); }).kind() == Kind::kConnectionLost);
    const ModbusError refused = error_of([&] { client.read_holding_registers(5, v); });
    CHECK(refused.kind() == Kind::kConnectFailed);
    CHECK(std::string(refused.what()) == "modbus-tcp://127.0.0.1:" + std::to_string(port) +
                                             "?unit=1: FC3 read holding registers 5 x1: cannot "
                                             "connect (Connection refused)");

    ModbusTcpEndpoint same_port;
    same_port.port = port;  // the restarted device comes back where it was
    server = ModbusServer::tcp(registers, same_port);
    ServingThread serving(*server);
    client.read_holding_registers(5, v);  // connects first: the last failure left it closed
    CHECK(v[0] == 55);
    CHECK(client.counters().connect_failures == 1);
    CHECK(client.counters().reconnects == 1);
}

TEST_CASE("TCP: a peer that never answers gives timeouts, one per try", "[modbus][tcp][threads]") {
    RegisterArray registers;
    // Listening (the kernel completes connects) but never polled: requests go unanswered.
    ModbusServer server = ModbusServer::tcp(registers, {});
    ModbusClientOptions options = fast(3);
    options.response_timeout = milliseconds(50);
    ModbusClient client(url_for(server), options);
    std::vector<std::uint16_t> v(2);
    const ModbusError e = error_of([&] { client.read_input_registers(0, v); });
    CHECK(e.kind() == Kind::kTimeout);
    CHECK(std::string(e.what()).find("(after 3 tries)") != std::string::npos);
    const ModbusClientCounters& c = client.counters();
    CHECK(c.attempts == 3);
    CHECK(c.retries == 2);
    CHECK(c.timeouts == 3);
    CHECK(c.reconnects == 2);  // TCP reconnects between tries
    CHECK(c.transactions == 0);
    CHECK(c.adu_bytes_sent ==
          3 * modbus_adu_bytes(ModbusFraming::kTcp, modbus_read_request_pdu_bytes()));
    CHECK(c.adu_bytes_received == 0);
}

TEST_CASE("TCP: byte counters agree between client and server", "[modbus][tcp][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    ServingThread serving(server);
    ModbusClient client(url_for(server), fast());
    std::vector<std::uint16_t> r(10);
    const std::vector<std::uint16_t> w(7, 3);
    client.read_holding_registers(0, r);      // 12 + 29
    client.read_input_registers(0, r);        // 12 + 29
    client.write_register(0, 1);              // 12 + 12
    client.write_registers(0, w);             // 27 + 12
    client.write_read_registers(0, w, 0, r);  // 31 + 29
    std::vector<std::uint16_t> bad(1);
    CHECK_THROWS_AS(client.read_holding_registers(999 + 1, bad), ModbusError);  // 12 + 9
    serving.stop();
    CHECK(client.counters().adu_bytes_sent == 12 + 12 + 12 + 27 + 31 + 12);
    CHECK(client.counters().adu_bytes_received == 29 + 29 + 12 + 12 + 29 + 9);
    CHECK(server.counters().adu_bytes_received == client.counters().adu_bytes_sent);
    CHECK(server.counters().adu_bytes_sent == client.counters().adu_bytes_received);
}

TEST_CASE("TCP: several clients at once", "[modbus][tcp][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    ServingThread serving(server);
    ModbusClient a(url_for(server, 1), fast());
    ModbusClient b(url_for(server, 2), fast());  // TCP answers every unit id
    for (std::uint16_t i = 0; i < 20; ++i) {
        a.write_register(i, i);
        b.write_register(static_cast<std::uint16_t>(100 + i), i);
    }
    std::vector<std::uint16_t> v(20);
    b.read_holding_registers(0, v);
    CHECK(v[19] == 19);
    a.read_holding_registers(100, v);
    CHECK(v[19] == 19);
    CHECK(server.open_connections() == 2);
}

TEST_CASE("client argument checks happen before anything is sent", "[modbus][tcp]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::tcp(registers, {});
    ModbusClient client(url_for(server), fast());
    std::vector<std::uint16_t> none;
    std::vector<std::uint16_t> many(126);
    std::vector<std::uint16_t> two(2);
    CHECK_THROWS_AS(client.read_holding_registers(0, none), std::invalid_argument);
    CHECK_THROWS_AS(client.read_input_registers(0, many), std::invalid_argument);
    CHECK_THROWS_AS(client.write_registers(0, std::span<const std::uint16_t>(many).first(124)),
                    std::invalid_argument);
    CHECK_THROWS_AS(client.read_holding_registers(65535, two), std::invalid_argument);
    CHECK(client.counters().attempts == 0);
    CHECK_THROWS_AS(ModbusClient("modbus-tcp://127.0.0.1:1", fast()), ModbusError);
}
