// The progress bar's text, and that it stays silent when not on a terminal.
#include <catch2/catch.hpp>
#include <cstdio>

#include "pathstream/host/progress.hpp"

using pathstream::host::ProgressBar;

TEST_CASE("progress lines show the bar, percentage and ETA", "[host][progress]") {
    CHECK(ProgressBar::render("plan", 0.0, 0.0) == "plan [..............................]   0%");
    CHECK(ProgressBar::render("plan", 0.5, 2.0) ==
          "plan [###############...............]  50%  ETA 2 s");
    CHECK(ProgressBar::render("plan", 1.0, 4.25) ==
          "plan [##############################] 100%  4.2 s");
    CHECK(ProgressBar::render("plan", 7.0, 1.0).find("100%") != std::string::npos);
}

TEST_CASE("a disabled bar writes nothing", "[host][progress]") {
    std::FILE* f = std::tmpfile();
    REQUIRE(f != nullptr);
    {
        ProgressBar bar("sim", f, false);
        bar.update(0.5);
        bar.finish();
    }
    CHECK(std::ftell(f) == 0);
    std::fclose(f);
}

TEST_CASE("a progress line fits the terminal: the bar narrows, then the detail is cut",
          "[host][progress]") {
    const std::string detail = "planning 43 %, queue 0.39 s, subpath 12/40, pen down, running";
    const std::string wide = ProgressBar::render("streaming", 0.5, 2.0, detail, {}, 200);
    CHECK(wide.find("[###############...............]") != std::string::npos);
    CHECK(wide.find(detail) != std::string::npos);
    for (const std::size_t width : {40u, 60u, 80u, 120u}) {
        const std::string line = ProgressBar::render("streaming", 0.5, 2.0, detail, {}, width);
        INFO(width << ": " << line);
        CHECK(line.size() <= width - 1);  // one column spare: no terminal wraps it
        CHECK(line.find("50%") != std::string::npos);
    }
    CHECK(ProgressBar::render("streaming", 0.5, 2.0, detail, {}, 80).find("[#####.....]") !=
          std::string::npos);
    CHECK(ProgressBar::render("streaming", 0.5, 2.0, detail, {}, 80).substr(76) == "...");
}

TEST_CASE("a given ETA replaces the wall-time extrapolation, an estimate is marked",
          "[host][progress]") {
    // After a resume the fraction counts the whole drawing while the wall time counts this
    // run only: the ETA must come from the motion left.
    CHECK(ProgressBar::render("streaming", 0.73, 1.0, "", {5.3, false}) ==
          "streaming [######################........]  73%  ETA 6 s");
    CHECK(ProgressBar::render("streaming", 0.15, 1.0, "", {173.0, true}) ==
          "streaming [#####.........................]  15%~  ETA ~2 min 53 s");
    // An estimate is never "done".
    CHECK(ProgressBar::render("streaming", 1.0, 1.0, "", {0.0, true}).find("ETA ~0 s") !=
          std::string::npos);
}

TEST_CASE("an interrupted bar ends where the work stopped, not at 100 %", "[host][progress]") {
    std::FILE* f = std::tmpfile();
    REQUIRE(f != nullptr);
    {
        ProgressBar bar("streaming", f, true);
        bar.update(0.42, "held", {12.0, false});
    }  // the destructor ends the line
    std::rewind(f);
    char text[512] = {};
    const std::size_t n = std::fread(text, 1, sizeof text - 1, f);
    std::fclose(f);
    const std::string out(text, n);
    INFO(out);
    CHECK(out.find(" 42%  ETA 12 s  held") != std::string::npos);
    CHECK(out.find("100%") == std::string::npos);
    CHECK(out.back() == '\n');
}
