#include "plugins/vision/marker_detector.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "plugins/camera_rig/marker_layout.h"

namespace crease::vision {

namespace {

float sample(const cv::Mat& g, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= g.cols || y0 + 1 >= g.rows) return -1.f;
  const float a = static_cast<float>(x - x0), b = static_cast<float>(y - y0);
  const uchar* r0 = g.ptr<uchar>(y0);
  const uchar* r1 = g.ptr<uchar>(y0 + 1);
  return (1 - b) * ((1 - a) * r0[x0] + a * r0[x0 + 1]) + b * ((1 - a) * r1[x0] + a * r1[x0 + 1]);
}

double side_len(const std::array<cv::Point2f, 4>& c) {
  double s = 0;
  for (int k = 0; k < 4; ++k) s += cv::norm(c[(k + 1) % 4] - c[k]);
  return s / 4;
}

}  // namespace

bool decode_tag(const cv::Mat& gray, const cv::aruco::Dictionary& dict, double correction_rate,
                std::array<cv::Point2f, 4>& corners, int& id) {
  // As aruco's bit extraction, but on the full-resolution image: warp the quad to 8x8 cells of
  // kPpc px, Otsu threshold, majority per cell (cell margins ignored), border must be black.
  constexpr int kPpc = 4;
  const int cells = dict.markerSize + 2;
  const int side = cells * kPpc;
  const cv::Point2f dst[4] = {{0, 0}, {float(side - 1), 0}, {float(side - 1), float(side - 1)}, {0, float(side - 1)}};
  cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(corners.begin(), corners.end()));
  box = (box + cv::Size(4, 4) - cv::Point(2, 2)) & cv::Rect(0, 0, gray.cols, gray.rows);
  if (box.width < 8 || box.height < 8) return false;
  cv::Point2f src[4];
  for (int k = 0; k < 4; ++k) src[k] = corners[k] - cv::Point2f(float(box.x), float(box.y));
  cv::Mat canon;
  cv::warpPerspective(gray(box), canon, cv::getPerspectiveTransform(src, dst), cv::Size(side, side),
                      cv::INTER_LINEAR);
  cv::Scalar mean, sd;
  cv::meanStdDev(canon, mean, sd);
  if (sd[0] < 5.0) return false;
  cv::Mat bin;
  cv::threshold(canon, bin, 125, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  cv::Mat bits(cells, cells, CV_8U);
  const int margin = 1;  // of kPpc: skip the cell's outer pixel ring
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
      const cv::Rect cell(c * kPpc + margin, r * kPpc + margin, kPpc - 2 * margin, kPpc - 2 * margin);
      bits.at<uchar>(r, c) = cv::countNonZero(bin(cell)) * 2 > cell.area() ? 1 : 0;
    }
  int border_errors = 0;
  for (int k = 0; k < cells; ++k)
    border_errors += bits.at<uchar>(0, k) + bits.at<uchar>(cells - 1, k) + (k > 0 && k < cells - 1
                         ? bits.at<uchar>(k, 0) + bits.at<uchar>(k, cells - 1) : 0);
  if (border_errors > 2) return false;
  int rotation = 0;
  if (!dict.identify(bits(cv::Rect(1, 1, dict.markerSize, dict.markerSize)), id, rotation, correction_rate))
    return false;
  if (rotation != 0) std::rotate(corners.begin(), corners.begin() + 4 - rotation, corners.end());
  return true;
}

bool refine_corners_edges(const cv::Mat& gray, std::array<cv::Point2f, 4>& corners) {
  const double side = side_len(corners);
  const double cell = side / 8.0;
  if (cell < 2.0) return false;
  cv::Point2d centre(0, 0);
  for (const auto& c : corners) centre += cv::Point2d(c) * 0.25;
  std::array<cv::Point2f, 4> cur = corners;
  for (int pass = 0; pass < 2; ++pass) {
    const double R = pass == 0 ? std::min(4.0, 0.6 * cell) : std::min(1.5, 0.4 * cell);
    const double step = pass == 0 ? 0.5 : 0.25;
    cv::Vec3d lines[4];  // a x + b y = c, (a, b) unit outward normal
    for (int k = 0; k < 4; ++k) {
      const cv::Point2d p0 = cur[k], p1 = cur[(k + 1) % 4];
      const cv::Point2d e = (p1 - p0) / cv::norm(p1 - p0);
      cv::Point2d n(e.y, -e.x);
      if ((0.5 * (p0 + p1) - centre).dot(n) < 0) n = -n;
      const int samples = std::clamp(static_cast<int>(cv::norm(p1 - p0) / 3), 6, 24);
      double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
      int m = 0;
      for (int q = 0; q < samples; ++q) {
        const double t = 0.15 + 0.7 * q / (samples - 1);
        const cv::Point2d p = p0 + t * (p1 - p0);
        // Profile along the outward normal; the edge is the steepest dark -> light rise.
        constexpr int kMax = 40;
        float prof[kMax];
        const int np = std::min(kMax, static_cast<int>(2 * R / step) + 3);
        const double s0 = -step * (np - 1) / 2.0;
        bool ok = true;
        for (int i = 0; i < np; ++i) {
          prof[i] = sample(gray, p.x + (s0 + i * step) * n.x, p.y + (s0 + i * step) * n.y);
          if (prof[i] < 0) ok = false;
        }
        if (!ok) continue;
        int best = -1;
        float bg = 0;
        for (int i = 1; i + 1 < np; ++i) {
          const float g = prof[i + 1] - prof[i - 1];
          if (g > bg) {
            bg = g;
            best = i;
          }
        }
        if (best < 2 || best > np - 3 || bg < 8.f) continue;
        // Centroid of the rise around the peak: unbiased for a symmetric blurred edge, also
        // where bilinear sampling makes the gradient flat between two pixel centres.
        const int w = static_cast<int>(std::lround(1.5 / step));
        double sw = 0, swi = 0;
        for (int i = std::max(1, best - w); i <= std::min(np - 2, best + w); ++i) {
          const double g = std::max(0.f, prof[i + 1] - prof[i - 1]);
          sw += g;
          swi += g * i;
        }
        const double s = s0 + (swi / sw) * step;
        const cv::Point2d ep = p + s * n;
        sx += ep.x;
        sy += ep.y;
        sxx += ep.x * ep.x;
        syy += ep.y * ep.y;
        sxy += ep.x * ep.y;
        ++m;
      }
      if (m < 4) return false;
      // Total least squares line through the edge points.
      const double mx = sx / m, my = sy / m;
      const double cxx = sxx / m - mx * mx, cyy = syy / m - my * my, cxy = sxy / m - mx * my;
      const double ang = 0.5 * std::atan2(2 * cxy, cxx - cyy);  // direction of the line
      cv::Point2d nn(-std::sin(ang), std::cos(ang));
      if (nn.dot(n) < 0) nn = -nn;
      lines[k] = cv::Vec3d(nn.x, nn.y, nn.x * mx + nn.y * my);
    }
    std::array<cv::Point2f, 4> next;
    for (int k = 0; k < 4; ++k) {
      const cv::Vec3d& l1 = lines[(k + 3) % 4];  // side ending at corner k
      const cv::Vec3d& l2 = lines[k];            // side starting at corner k
      const double det = l1[0] * l2[1] - l1[1] * l2[0];
      if (std::abs(det) < 1e-6) return false;
      const cv::Point2d x((l1[2] * l2[1] - l1[1] * l2[2]) / det, (l1[0] * l2[2] - l1[2] * l2[0]) / det);
      if (cv::norm(x - cv::Point2d(cur[k])) > 0.5 * side) return false;
      next[k] = cv::Point2f(x);
    }
    cur = next;
  }
  corners = cur;
  return true;
}

MarkerDetector::MarkerDetector(const DetectorConfig& cfg)
    : cfg_(cfg), dict_(dictionary_by_name(cfg.dictionary)), params_(cv::aruco::DetectorParameters::create()) {
  // Tags are 8 cells wide, searched at >= ~10 px: one threshold window a few cells wide.
  params_->adaptiveThreshWinSizeMin = cfg.threshold_window_min;
  params_->adaptiveThreshWinSizeMax = cfg.threshold_window_max;
  params_->adaptiveThreshWinSizeStep = cfg.threshold_window_step;
  params_->errorCorrectionRate = cfg.error_correction_rate;
  params_->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
}

void MarkerDetector::reset() {
  last_.clear();
  prev_.clear();
  frames_since_full_ = 0;
}

void MarkerDetector::search(const cv::Mat& gray, const cv::Rect& roi, int dec, std::vector<MarkerDetection>& out) {
  cv::Mat view = gray(roi);
  if (dec > 1) {
    cv::resize(view, small_, cv::Size(view.cols / dec, view.rows / dec), 0, 0, cv::INTER_AREA);
    view = small_;
  }
  const double max_dim = std::max(view.cols, view.rows);
  params_->minMarkerPerimeterRate = std::clamp(4.0 * cfg_.min_marker_px / dec / max_dim, 0.005, 0.5);
  params_->maxMarkerPerimeterRate = 4.0;
  corners_.clear();
  ids_.clear();
  rejected_.clear();
  cv::aruco::detectMarkers(view, dict_, corners_, ids_, params_, rejected_);
  if (dec > 1) {
    // Tags too small to decode at reduced resolution: decode their quads at full resolution.
    for (const auto& q : rejected_) {
      std::array<cv::Point2f, 4> c;
      for (int k = 0; k < 4; ++k)
        c[k] = cv::Point2f(q[static_cast<std::size_t>(k)].x * dec + 0.5f * (dec - 1) + roi.x,
                           q[static_cast<std::size_t>(k)].y * dec + 0.5f * (dec - 1) + roi.y);
      // The reduced-resolution quad can be a pixel or two off: refine before reading bits.
      std::array<cv::Point2f, 4> r = c;
      int id = -1;
      if (refine_corners_edges(gray, r) && decode_tag(gray, *dict_, cfg_.error_correction_rate, r, id)) {
        c = r;
      } else if (!decode_tag(gray, *dict_, cfg_.error_correction_rate, c, id)) {
        continue;
      }
      if (cfg_.max_id >= 0 && id > cfg_.max_id) continue;
      out.push_back({id, c});
    }
  }
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    if (cfg_.max_id >= 0 && ids_[i] > cfg_.max_id) continue;
    MarkerDetection d;
    d.id = ids_[i];
    for (int k = 0; k < 4; ++k) {
      // INTER_AREA pixel i covers source [dec*i, dec*i + dec): centre at dec*i + (dec-1)/2.
      const cv::Point2f p = corners_[i][static_cast<std::size_t>(k)];
      d.corners[k] = cv::Point2f(p.x * dec + 0.5f * (dec - 1) + roi.x, p.y * dec + 0.5f * (dec - 1) + roi.y);
    }
    out.push_back(d);
  }
}

void MarkerDetector::detect(const cv::Mat& gray, std::vector<MarkerDetection>& out) {
  out.clear();
  const cv::Rect full(0, 0, gray.cols, gray.rows);
  if (last_.empty() || ++frames_since_full_ >= cfg_.full_search_interval) {
    frames_since_full_ = 0;
    ++full_searches_;
    search(gray, full, cfg_.decimate, out);
  } else {
    // One region: the union of the predicted boxes (constant velocity per tag), each grown by
    // roi_margin sides. The sheet is one piece, so tags hidden last frame (a hand moved away)
    // lie between or next to the tracked ones.
    cv::Rect roi;
    for (const auto& m : last_) {
      std::array<cv::Point2f, 4> c = m.corners;
      for (const auto& p : prev_)
        if (p.id == m.id)
          for (int k = 0; k < 4; ++k) c[k] += m.corners[k] - p.corners[k];
      const cv::Rect b = cv::boundingRect(std::vector<cv::Point2f>(c.begin(), c.end()));
      const int margin = static_cast<int>(cfg_.roi_margin * side_len(c)) + 4;
      roi |= b + cv::Size(2 * margin, 2 * margin) - cv::Point(margin, margin);
    }
    roi &= full;
    if (roi.width >= 16 && roi.height >= 16) search(gray, roi, cfg_.decimate, out);
  }
  for (auto& d : out) {
    if (cfg_.refine == CornerRefine::kEdges) {
      refine_corners_edges(gray, d.corners);
    } else if (cfg_.refine == CornerRefine::kSubPix) {
      std::vector<cv::Point2f> c(d.corners.begin(), d.corners.end());
      const int w = std::max(2, static_cast<int>(side_len(d.corners) / 16));
      cv::cornerSubPix(gray, c, cv::Size(w, w), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
      std::copy(c.begin(), c.end(), d.corners.begin());
    }
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  // The same id twice: one tag found twice (keep one) or two different places (a wrong read:
  // neither can be trusted, drop both).
  auto centre = [](const MarkerDetection& d) { return 0.25f * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]); };
  for (std::size_t i = 0; i + 1 < out.size();) {
    if (out[i].id != out[i + 1].id) {
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    bool same_place = true;
    for (; j < out.size() && out[j].id == out[i].id; ++j)
      same_place = same_place && cv::norm(centre(out[j]) - centre(out[i])) < 0.25 * side_len(out[i].corners);
    out.erase(out.begin() + static_cast<long>(same_place ? i + 1 : i), out.begin() + static_cast<long>(j));
    if (same_place) ++i;
  }
  prev_ = last_;
  last_ = out;
}

void detect_stock(const cv::Mat& gray, const cv::Ptr<cv::aruco::Dictionary>& dict,
                  std::vector<MarkerDetection>& out) {
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dict, corners, ids);
  out.clear();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    MarkerDetection d;
    d.id = ids[i];
    for (int k = 0; k < 4; ++k) d.corners[k] = corners[i][static_cast<std::size_t>(k)];
    out.push_back(d);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
}

}  // namespace crease::vision
