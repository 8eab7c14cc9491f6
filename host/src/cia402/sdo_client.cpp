// Expedited SDO client (CiA 301): one request, one response, retried on timeout; aborts
// decoded into messages that name node, object and the reason.
#include <cstdio>
#include <string>

#include "frame_bytes.hpp"
#include "pathstream/host/cia402_master.hpp"

namespace pathstream::host {

using namespace cia402;

namespace {

std::string object_name(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
    char b[48];
    std::snprintf(b, sizeof b, "node %u: SDO 0x%04X:%02X", node, index, sub);
    return b;
}

}  // namespace

std::uint32_t Cia402Master::sdo_transfer(std::uint8_t node, const hal::CanFrame& request,
                                         std::uint8_t* size) {
    const auto index = static_cast<std::uint16_t>(get_le(request, 1, 2));
    const std::uint8_t sub = request.data[3];
    const bool upload = request.data[0] == kSdoUploadRequest;
    const std::string what = object_name(node, index, sub) + (upload ? " read" : " write");
    hal::CanFrame f;
    for (unsigned attempt = 0; attempt < options_.sdo_attempts; ++attempt) {
        sdo_node_ = node;
        sdo_done_ = false;
        send(request);
        const std::uint64_t deadline = clock_.now() + std::uint64_t{options_.sdo_timeout_ms} * 1000;
        while (!sdo_done_) {
            const std::uint64_t now = clock_.now();
            if (now >= deadline) break;
            if (bus_.receive(f, static_cast<std::uint32_t>(deadline - now))) handle(f);
            // A response to another object (a late answer to an earlier try) is not ours.
            if (sdo_done_ && (get_le(sdo_response_, 1, 2) != index || sdo_response_.data[3] != sub))
                sdo_done_ = false;
        }
        sdo_node_ = 0;
        if (!sdo_done_) continue;
        const hal::CanFrame& r = sdo_response_;
        if (r.data[0] == kSdoAbort) {
            const std::uint32_t code = get_le(r, 4, 4);
            throw SdoError(what + " refused: " + sdo_abort_text(code), code);
        }
        if (!upload) {
            if (r.data[0] != kSdoDownloadResponse)
                throw SdoError(what + ": unexpected response", kAbortCommand);
            return 0;
        }
        if ((r.data[0] & 0xE0) != kSdoUploadResponse || (r.data[0] & 0x02) == 0) {
            throw SdoError(
                what + ": not an expedited upload response (segmented transfers are not supported)",
                kAbortCommand);
        }
        const std::uint8_t n =
            (r.data[0] & 0x01) != 0 ? static_cast<std::uint8_t>(4 - ((r.data[0] >> 2) & 3)) : 4;
        if (size != nullptr) *size = n;
        return get_le(r, 4, n);
    }
    // Tell the server the transfer is over, so a late request does not linger in it.
    hal::CanFrame abort = make_frame(kSdoRequestBase + node, 8);
    abort.data[0] = kSdoAbort;
    put_le(abort, 1, 2, index);
    abort.data[3] = sub;
    put_le(abort, 4, 4, kAbortTimeout);
    send(abort);
    throw SdoError(what + ": no response in " + std::to_string(options_.sdo_attempts) +
                       " tries of " + std::to_string(options_.sdo_timeout_ms) + " ms (is node " +
                       std::to_string(node) + " on the bus?)",
                   kAbortTimeout);
}

void Cia402Master::sdo_download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                                std::uint32_t value, std::uint8_t size) {
    if (size != 1 && size != 2 && size != 4)
        throw std::invalid_argument("SDO download of 1, 2 or 4 bytes");
    hal::CanFrame f = make_frame(kSdoRequestBase + node, 8);
    f.data[0] = static_cast<std::uint8_t>(kSdoDownloadRequest | (4 - size) << 2 | 0x03);
    put_le(f, 1, 2, index);
    f.data[3] = sub;
    put_le(f, 4, size, value);
    sdo_transfer(node, f, nullptr);
}

std::uint32_t Cia402Master::sdo_upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                                       std::uint8_t* size) {
    hal::CanFrame f = make_frame(kSdoRequestBase + node, 8);
    f.data[0] = kSdoUploadRequest;
    put_le(f, 1, 2, index);
    f.data[3] = sub;
    return sdo_transfer(node, f, size);
}

}  // namespace pathstream::host
