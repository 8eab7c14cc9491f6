// Job messages as a machine takes them from the broker (docs/mqtt.md, "Jobs"): what is read,
// what is refused and why, and the message a busy machine passes on.
#include <catch2/catch.hpp>
#include <stdexcept>
#include <string>

#include "serve/job_message.hpp"

using namespace pathstream::host::serve;

namespace {

std::string refusal(const std::string& payload, std::size_t limit = 1000) {
    try {
        (void)parse_job_message(payload, limit);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST_CASE("a job message is read whole", "[mqtt][jobs]") {
    const JobMessage j = parse_job_message(
        R"({"id": "print-0007", "file": "rose.json", "drawing": "{\"points\": []}",
            "options": {"fit": "a4", "margin": 10}, "kind": "pen_plotter", "submitted": 1.5})",
        1000);
    CHECK(j.id == "print-0007");
    CHECK(j.file == "rose.json");
    CHECK(j.drawing == R"({"points": []})");
    CHECK(j.options == nlohmann::json{{"fit", "a4"}, {"margin", 10}});
    CHECK(j.bounces == 0);
    // No options: none.
    CHECK(parse_job_message(R"({"id": "a", "file": "a.ngc", "drawing": "G0 X1"})", 100).options ==
          nlohmann::json::object());
}

TEST_CASE("a job message that is wrong is refused with the reason", "[mqtt][jobs]") {
    CHECK(refusal("not json") == "job: not JSON");
    CHECK(refusal("[1]") == "job: want a JSON object");
    CHECK(refusal(R"({"file": "a.svg", "drawing": ""})") == "job: no \"id\"");
    CHECK(refusal(R"({"id": 7, "file": "a.svg", "drawing": ""})") ==
          "job: \"id\" must be a string");
    CHECK(refusal(R"({"id": "a/b", "file": "a.svg", "drawing": ""})") ==
          "job: \"id\" \"a/b\": only letters, digits, _ and - (it is a topic level)");
    CHECK(refusal(R"({"id": "", "file": "a.svg", "drawing": ""})") ==
          "job: \"id\" must have 1 to 64 characters");
    CHECK(refusal(R"({"id": ")" + std::string(65, 'x') + R"(", "file": "a.svg", "drawing": ""})") ==
          "job: \"id\" must have 1 to 64 characters");
    CHECK(refusal(R"({"id": "a", "file": "../a.svg", "drawing": ""})") ==
          "job: \"file\" must be a plain file name (no directory)");
    CHECK(refusal(R"({"id": "a", "file": ".json", "drawing": ""})") ==
          "job: \"file\" must be a plain file name (no directory)");
    CHECK(refusal(R"({"id": "a", "file": "a.exe", "drawing": ""})") ==
          "job: \"file\" \"a.exe\": no reader takes it (.json .csv .svg .ngc .gcode .nc .bpt)");
    CHECK(refusal(R"({"id": "a", "file": "a.svg"})") == "job: no \"drawing\"");
    CHECK(refusal(R"({"id": "a", "file": "a.svg", "drawing": "12345"})", 4) ==
          "job: the drawing has 5 bytes, more than the 4 this machine takes");
    CHECK(refusal(R"({"id": "a", "file": "a.svg", "drawing": "", "options": []})") ==
          "job: \"options\" must be an object");
    CHECK(refusal(R"({"id": "a", "file": "a.svg", "drawing": "", "bounces": -1})") ==
          "job: \"bounces\" must be a count");
}

TEST_CASE("a job passed on reads back as itself, counted once more", "[mqtt][jobs]") {
    JobMessage j = parse_job_message(
        R"({"id": "j-1", "file": "a.csv", "drawing": "0,0\n1,1\n", "options": {"keep_order": true}})",
        100);
    ++j.bounces;
    const JobMessage back = parse_job_message(job_message_text(j), 100);
    CHECK(back.id == j.id);
    CHECK(back.file == j.file);
    CHECK(back.drawing == j.drawing);
    CHECK(back.options == j.options);
    CHECK(back.bounces == 1);
}
