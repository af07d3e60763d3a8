#include "plugins/camera_rig/marker_layout.h"

#include <algorithm>
#include <fstream>

#include <yaml-cpp/yaml.h>

#include "core/assert.h"

namespace crease::vision {

int MarkerLayout::index_of(int id) const {
  for (std::size_t i = 0; i < markers.size(); ++i)
    if (markers[i].id == id) return static_cast<int>(i);
  return -1;
}

int MarkerLayout::max_id() const {
  int m = -1;
  for (const auto& p : markers) m = std::max(m, p.id);
  return m;
}

cv::Size2d paper_size_mm(const std::string& paper) {
  if (paper == "a4") return {210.0, 297.0};
  if (paper == "a3") return {297.0, 420.0};
  if (paper == "a5") return {148.0, 210.0};
  if (paper == "letter") return {215.9, 279.4};
  throw crease::ConfigError("unknown paper '" + paper + "' (a3, a4, a5, letter)");
}

cv::Ptr<cv::aruco::Dictionary> dictionary_by_name(const std::string& name) {
  using namespace cv::aruco;
  static const std::pair<const char*, PREDEFINED_DICTIONARY_NAME> kNames[] = {
      {"apriltag36h11", DICT_APRILTAG_36h11}, {"apriltag36h10", DICT_APRILTAG_36h10},
      {"apriltag25h9", DICT_APRILTAG_25h9},   {"apriltag16h5", DICT_APRILTAG_16h5},
      {"4x4_50", DICT_4X4_50},                {"4x4_1000", DICT_4X4_1000},
      {"5x5_1000", DICT_5X5_1000},            {"6x6_1000", DICT_6X6_1000},
      {"aruco_original", DICT_ARUCO_ORIGINAL}};
  for (const auto& [n, d] : kNames)
    if (name == n) return getPredefinedDictionary(d);
  throw crease::ConfigError("unknown dictionary '" + name +
                            "' (apriltag36h11, apriltag36h10, apriltag25h9, apriltag16h5, "
                            "4x4_50, 4x4_1000, 5x5_1000, 6x6_1000, aruco_original)");
}

MarkerLayout make_layout(const LayoutSpec& spec) {
  const cv::Size2d page = paper_size_mm(spec.paper);
  const auto dict = dictionary_by_name(spec.dictionary);
  crease::require_input(spec.cols >= 1 && spec.rows >= 1, "grid must be at least 1x1");
  crease::require_input(spec.marker_mm > 0, "marker size must be positive");
  const double pitch_u = page.width / spec.cols;
  const double pitch_v = page.height / spec.rows;
  // A quiet zone of one cell on every side of every tag keeps its outer edge detectable.
  const double cell = spec.marker_mm / (dict->markerSize + 2);
  crease::require_input(spec.marker_mm + 2 * cell <= std::min(pitch_u, pitch_v),
                        "markers of " + std::to_string(spec.marker_mm) + " mm do not fit a " +
                            std::to_string(spec.cols) + "x" + std::to_string(spec.rows) + " grid on " +
                            spec.paper + " with a one-cell quiet zone");
  const int faces = spec.double_sided ? 2 : 1;
  const int needed = spec.first_id + faces * spec.cols * spec.rows;
  crease::require_input(needed <= dict->bytesList.rows,
                        "layout needs ids up to " + std::to_string(needed - 1) + " but " + spec.dictionary +
                            " has " + std::to_string(dict->bytesList.rows));

  MarkerLayout L;
  L.dictionary = spec.dictionary;
  L.paper = spec.paper;
  L.sheet_w_mm = page.width;
  L.sheet_h_mm = page.height;
  L.marker_mm = spec.marker_mm;
  const double h = spec.marker_mm / 2;
  int id = spec.first_id;
  for (int f = 0; f < faces; ++f) {
    for (int r = 0; r < spec.rows; ++r) {
      for (int c = 0; c < spec.cols; ++c) {
        MarkerPlacement m;
        m.id = id++;
        m.face = f == 0 ? Face::kFront : Face::kBack;
        // Position on the page as printed on this face (for the back: as seen from the back).
        const double pu = (c + 0.5) * pitch_u, pv = (r + 0.5) * pitch_v;
        const std::array<cv::Point2d, 4> page_corners = {
            cv::Point2d{pu - h, pv - h}, {pu + h, pv - h}, {pu + h, pv + h}, {pu - h, pv + h}};
        if (m.face == Face::kFront) {
          m.centre_mm = {pu, pv};
          m.corners_mm = page_corners;
        } else {  // back page is mirrored in u relative to the front frame
          m.centre_mm = {page.width - pu, pv};
          for (int k = 0; k < 4; ++k)
            m.corners_mm[k] = {page.width - page_corners[k].x, page_corners[k].y};
        }
        L.markers.push_back(m);
      }
    }
  }
  return L;
}

void save_layout(const MarkerLayout& L, const std::string& path) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Comment(
      "Crease marker layout. Sheet coordinates (u, v) in mm of the FRONT face: origin top-left of "
      "the printed front page, u right along the short edge, v down along the long edge. Back-face "
      "markers are given at the same physical point in front coordinates (the back page is printed "
      "mirrored: duplex, flip on long edge). Corners in detector order TL, TR, BR, BL as the tag "
      "is read.");
  out << YAML::Key << "dictionary" << YAML::Value << L.dictionary;
  out << YAML::Key << "paper" << YAML::Value << L.paper;
  out << YAML::Key << "sheet_size_mm" << YAML::Value << YAML::Flow << YAML::BeginSeq << L.sheet_w_mm
      << L.sheet_h_mm << YAML::EndSeq;
  out << YAML::Key << "origin" << YAML::Value << "top-left of front face, u right, v down";
  out << YAML::Key << "back_face" << YAML::Value << "front coordinates, page mirrored in u";
  out << YAML::Key << "marker_mm" << YAML::Value << L.marker_mm;
  out << YAML::Key << "markers" << YAML::Value << YAML::BeginSeq;
  for (const auto& m : L.markers) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "id" << YAML::Value << m.id;
    out << YAML::Key << "face" << YAML::Value << (m.face == Face::kFront ? "front" : "back");
    out << YAML::Key << "centre" << YAML::Value << YAML::BeginSeq << m.centre_mm.x << m.centre_mm.y
        << YAML::EndSeq;
    out << YAML::Key << "corners" << YAML::Value << YAML::BeginSeq;
    for (const auto& c : m.corners_mm) out << YAML::BeginSeq << c.x << c.y << YAML::EndSeq;
    out << YAML::EndSeq << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  std::ofstream f(path);
  if (!f) throw crease::Error(path + ": cannot open for writing");
  f << out.c_str() << "\n";
  if (!f) throw crease::Error(path + ": write failed");
}

namespace {

// "PATH:LINE:COLUMN: KEY: why", the place of `at` (the value, or the map a key is missing from).
[[noreturn]] void fail(const std::string& path, const YAML::Node& at, const std::string& key,
                       const std::string& why) {
  const YAML::Mark m = at.IsDefined() ? at.Mark() : YAML::Mark::null_mark();
  throw crease::ConfigError(crease::SourceLoc{path, m.line + 1, m.column + 1}, key, why);
}

YAML::Node need(const YAML::Node& n, const char* key, const std::string& path, const std::string& ctx) {
  if (!n[key]) fail(path, n, ctx + key, "missing");
  return n[key];
}

cv::Point2d point(const YAML::Node& n, const std::string& path, const std::string& key) {
  if (!n.IsSequence() || n.size() != 2) fail(path, n, key, "expected [u, v]");
  return {n[0].as<double>(), n[1].as<double>()};
}

}  // namespace

MarkerLayout load_layout(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw crease::ConfigError(path + ": cannot read layout file");
  } catch (const YAML::Exception& e) {
    throw crease::ConfigError(path + ": line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  MarkerLayout L;
  try {
    const YAML::Node dictionary = need(root, "dictionary", path, "");
    L.dictionary = dictionary.as<std::string>();
    try {
      dictionary_by_name(L.dictionary);
    } catch (const crease::ConfigError& e) {
      fail(path, dictionary, "dictionary", e.what());
    }
    L.paper = root["paper"] ? root["paper"].as<std::string>() : std::string("custom");
    const auto size = need(root, "sheet_size_mm", path, "");
    const cv::Point2d s = point(size, path, "sheet_size_mm");
    L.sheet_w_mm = s.x;
    L.sheet_h_mm = s.y;
    if (!(L.sheet_w_mm > 0 && L.sheet_h_mm > 0)) fail(path, size, "sheet_size_mm", "must be positive");
    L.marker_mm = need(root, "marker_mm", path, "").as<double>();
    const auto ms = need(root, "markers", path, "");
    if (!ms.IsSequence()) fail(path, ms, "markers", "expected a list");
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const std::string ctx = "markers[" + std::to_string(i) + "].";
      MarkerPlacement m;
      m.id = need(ms[i], "id", path, ctx).as<int>();
      const YAML::Node face_node = need(ms[i], "face", path, ctx);
      const auto face = face_node.as<std::string>();
      if (face != "front" && face != "back") fail(path, face_node, ctx + "face", "expected front or back");
      m.face = face == "front" ? Face::kFront : Face::kBack;
      m.centre_mm = point(need(ms[i], "centre", path, ctx), path, ctx + "centre");
      const auto cs = need(ms[i], "corners", path, ctx);
      if (!cs.IsSequence() || cs.size() != 4) fail(path, cs, ctx + "corners", "expected 4 corners");
      for (int k = 0; k < 4; ++k) m.corners_mm[k] = point(cs[k], path, ctx + "corners");
      if (L.index_of(m.id) >= 0) fail(path, ms[i]["id"], ctx + "id", "duplicate id " + std::to_string(m.id));
      L.markers.push_back(m);
    }
  } catch (const YAML::Exception& e) {
    throw crease::ConfigError(path + ": line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  return L;
}

}  // namespace crease::vision
