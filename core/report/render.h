// Renders a TimingReport as text, JSON or HTML. Off the RT threads only.
//
// text: cyclictest's `-h` histogram output (one column per loop's wake-up latency, one row
//       per microsecond), preceded and followed by '#' comment lines with Crease's extras,
//       so scripts that plot cyclictest histograms read it unchanged.
// json: the data model, field for field (report_json.h), parseable back.
// html: one self-contained file: inline CSS and SVG plots, no scripts, no network.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/report/timing_report.h"

namespace crease::report {

enum class Format { text, json, html };

[[nodiscard]] std::optional<Format> parse_format(std::string_view name);  // "text"|"json"|"html"
[[nodiscard]] const char* to_string(Format f) noexcept;
[[nodiscard]] const char* file_extension(Format f) noexcept;  // "txt", "json", "html"

[[nodiscard]] std::string render_text(const TimingReport& report);
[[nodiscard]] std::string render_json(const TimingReport& report);  // pretty, 2-space indent
[[nodiscard]] std::string render_html(const TimingReport& report);
[[nodiscard]] std::string render(const TimingReport& report, Format format);
// TEXT for HTML, element content and attribute values alike (& < > " ' as entities).
[[nodiscard]] std::string html_escape(std::string_view text);

// Writes DIR/BASENAME.{txt,json,html} (DIR created when missing) and returns the paths.
// @throws crease::Error naming the file that could not be written.
std::vector<std::string> write_report_files(const TimingReport& report, const std::string& dir,
                                            const std::string& basename = "crease-report");

// Rows of the text histogram: samples above this many microseconds count as overflow.
inline constexpr int kTextHistogramMaxUs = 10000;

}  // namespace crease::report
