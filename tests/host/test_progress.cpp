// The progress bar's text, and that it stays silent when not on a terminal.
#include <catch2/catch.hpp>

#include <cstdio>

#include "pathstream/host/progress.hpp"

using pathstream::host::ProgressBar;

TEST_CASE("progress lines show the bar, percentage and ETA", "[host][progress]") {
    CHECK(ProgressBar::render("plan", 0.0, 0.0) == "plan [..............................]   0%");
    CHECK(ProgressBar::render("plan", 0.5, 2.0) == "plan [###############...............]  50%  ETA 2 s");
    CHECK(ProgressBar::render("plan", 1.0, 4.25) == "plan [##############################] 100%  4.2 s");
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
