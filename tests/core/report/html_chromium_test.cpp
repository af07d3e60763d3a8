// Renders the HTML report in headless Chromium and checks the screenshot is not blank.
// Label `slow`; skipped with a message when chromium is not installed.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "core/report/render.h"
#include "core/report/report_fixture.h"

namespace {

// Reads PNG width/height from the IHDR chunk; false when the file is not a PNG.
bool png_size(const std::string& path, unsigned& w, unsigned& h) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[24] = {};
  if (!in.read(reinterpret_cast<char*>(b), sizeof(b))) return false;
  if (b[0] != 0x89 || b[1] != 'P' || b[2] != 'N' || b[3] != 'G') return false;
  w = (b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19];
  h = (b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23];
  return true;
}

}  // namespace

TEST_CASE("the HTML report renders in headless chromium") {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) {
    MESSAGE("SKIPPED: chromium is not installed");
    return;
  }
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("crease_html_" + std::to_string(::getpid()));
  fs::create_directories(dir / "profile");
  const fs::path html = dir / "report.html";
  const fs::path png = dir / "out.png";
  {
    std::ofstream out(html);
    out << crease::report::render_html(crease::report::testing::report_fixture());
  }
  const std::string cmd =
      "cd " + dir.string() +
      " && timeout 60 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
      " --disable-background-networking --disable-component-update --disable-sync"
      " --user-data-dir=" + (dir / "profile").string() +
      " --screenshot=" + png.string() + " --window-size=1200,900 file://" + html.string() +
      " >" + (dir / "chromium.log").string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  CHECK(rc == 0);
  REQUIRE(fs::exists(png));
  unsigned w = 0, h = 0;
  REQUIRE(png_size(png.string(), w, h));
  CHECK(w == 1200);
  CHECK(h == 900);
  // A blank white page compresses to a few KB; text, tables and plots make it much larger.
  CHECK(fs::file_size(png) > 20000);
  fs::remove_all(dir);
}
