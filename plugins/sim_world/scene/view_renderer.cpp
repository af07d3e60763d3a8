#include "plugins/sim_world/scene/view_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

namespace crease::vision {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kPaperBlack = 30.f, kPaperWhite = 225.f;  // albedo range in grey levels

std::vector<cv::Mat> pyramid(const cv::Mat& tex8) {
  std::vector<cv::Mat> p(1);
  tex8.convertTo(p[0], CV_32F);
  while (std::min(p.back().cols, p.back().rows) > 16) {
    cv::Mat d;
    cv::pyrDown(p.back(), d);  // dst(i) is centred on src(2i): level coordinates scale by 1/2
    p.push_back(d);
  }
  return p;
}

float bilinear(const cv::Mat& m, double x, double y) {
  x = std::clamp(x, 0.0, m.cols - 1.001);
  y = std::clamp(y, 0.0, m.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float a = static_cast<float>(x - x0), b = static_cast<float>(y - y0);
  const float* r0 = m.ptr<float>(y0);
  const float* r1 = m.ptr<float>(y0 + 1);
  return (1 - b) * ((1 - a) * r0[x0] + a * r0[x0 + 1]) + b * ((1 - a) * r1[x0] + a * r1[x0 + 1]);
}

void draw_background(cv::Mat& img, cv::RNG& rng, bool clutter) {
  // Table: smooth low-contrast variation around mid grey.
  cv::Mat small(12, 16, CV_32F);
  rng.fill(small, cv::RNG::UNIFORM, 70.0, 110.0);
  cv::resize(small, img, img.size(), 0, 0, cv::INTER_CUBIC);
  if (!clutter) return;
  for (int k = 0; k < 40; ++k) {
    const cv::Point p(rng.uniform(0, img.cols), rng.uniform(0, img.rows));
    const cv::Point q = p + cv::Point(rng.uniform(-200, 200), rng.uniform(-200, 200));
    const double g = rng.uniform(0.0, 255.0);
    switch (k % 3) {
      case 0: cv::rectangle(img, p, q, cv::Scalar(g), rng.uniform(0, 2) ? -1 : 3, cv::LINE_AA); break;
      case 1: cv::line(img, p, q, cv::Scalar(g), rng.uniform(1, 8), cv::LINE_AA); break;
      default: cv::circle(img, p, rng.uniform(5, 80), cv::Scalar(g), -1, cv::LINE_AA); break;
    }
  }
}

// Palm ellipse and four or five finger capsules, skin-like grey with soft shading.
void draw_hand(cv::Mat& img, cv::Mat& mask, cv::RNG& rng, const cv::Rect& region) {
  const cv::Point2d c(region.x + rng.uniform(0.0, 1.0) * region.width,
                      region.y + rng.uniform(0.0, 1.0) * region.height);
  const double scale = rng.uniform(0.6, 1.2) * std::max(40.0, 0.22 * std::min(region.width, region.height));
  const double ang = rng.uniform(0.0, 2 * CV_PI);
  const double g = rng.uniform(120.0, 200.0);
  const cv::Size axes(static_cast<int>(scale * 0.55), static_cast<int>(scale * 0.45));
  cv::ellipse(img, c, axes, ang * 180 / CV_PI, 0, 360, cv::Scalar(g), -1, cv::LINE_AA);
  cv::ellipse(mask, c, axes, ang * 180 / CV_PI, 0, 360, cv::Scalar(255), -1, cv::LINE_8);
  const int fingers = rng.uniform(4, 6);
  for (int f = 0; f < fingers; ++f) {
    const double a = ang + (f - (fingers - 1) / 2.0) * 0.35;
    const double len = scale * rng.uniform(0.7, 1.1);
    const cv::Point2d base = c + 0.4 * scale * cv::Point2d(std::cos(a), std::sin(a));
    const cv::Point2d tip = base + len * cv::Point2d(std::cos(a), std::sin(a));
    const int thick = std::max(4, static_cast<int>(scale * 0.16));
    const double gf = g * rng.uniform(0.9, 1.05);
    cv::line(img, base, tip, cv::Scalar(gf), thick, cv::LINE_AA);
    cv::line(mask, base, tip, cv::Scalar(255), thick + 2, cv::LINE_8);
  }
}

}  // namespace

ViewRenderer::ViewRenderer(const cv::Mat& front, const cv::Mat& back, double ppm,
                           std::vector<Camera> cameras)
    : front_pyr_(pyramid(front)), back_pyr_(pyramid(back)), ppm_(ppm), cameras_(std::move(cameras)) {
  for (const Camera& cam : cameras_) {
    // Exact undistortion on a grid every kStep pixels, bilinear in between: the mapping is
    // smooth, the interpolation error is ~1e-3 px and the map costs 1/64 of the exact one.
    constexpr int kStep = 8;
    const int gw = (cam.width - 1) / kStep + 2, gh = (cam.height - 1) / kStep + 2;
    cv::Mat grid(gh, gw, CV_64FC2);
    for (int gy = 0; gy < gh; ++gy)
      for (int gx = 0; gx < gw; ++gx) {
        const cv::Point2d n = cam.undistort({double(gx * kStep), double(gy * kStep)});
        grid.at<cv::Vec2d>(gy, gx) = cv::Vec2d(n.x, n.y);
      }
    cv::Mat rays(cam.height, cam.width, CV_32FC2);
    for (int y = 0; y < cam.height; ++y) {
      const int gy = y / kStep;
      const double b = double(y - gy * kStep) / kStep;
      auto* row = rays.ptr<cv::Vec2f>(y);
      for (int x = 0; x < cam.width; ++x) {
        const int gx = x / kStep;
        const double a = double(x - gx * kStep) / kStep;
        const cv::Vec2d v = (1 - b) * ((1 - a) * grid.at<cv::Vec2d>(gy, gx) + a * grid.at<cv::Vec2d>(gy, gx + 1)) +
                            b * ((1 - a) * grid.at<cv::Vec2d>(gy + 1, gx) + a * grid.at<cv::Vec2d>(gy + 1, gx + 1));
        row[x] = cv::Vec2f(static_cast<float>(v[0]), static_cast<float>(v[1]));
      }
    }
    rays_.push_back(rays);
    ray_bounds_.push_back(ray_bounds(rays));
  }
}

void ViewRenderer::render(int ci, const SheetMesh& mesh, const RenderOptions& opt,
                          RenderedView& out, std::span<const SceneShape> shapes) const {
  const Camera& cam = cameras_.at(static_cast<std::size_t>(ci));
  const cv::Mat& rays = rays_[static_cast<std::size_t>(ci)];
  cv::RNG rng(opt.seed * 1000003ULL + static_cast<std::uint64_t>(ci) * 7919ULL + 17ULL);
  cv::Mat img(cam.height, cam.width, CV_32F);
  draw_background(img, rng, opt.clutter);
  out.depth.create(cam.height, cam.width, CV_32F);
  out.depth.setTo(cv::Scalar(kInf));
  const cv::Vec3d light = cv::normalize(cv::Vec3d(0.3, -0.2, 1.0));
  const cv::Vec3d cam_centre = cam.centre_world();
  cv::Rect2d sheet_box;
  bool any = false;

  auto draw_triangle = [&](int ia, int ja, int ib, int jb, int ic, int jc) {
    const cv::Vec3d A = mesh.node(ia, ja), B = mesh.node(ib, jb), C = mesh.node(ic, jc);
    const cv::Point2d a = mesh.node_uv(ia, ja), b = mesh.node_uv(ib, jb), c = mesh.node_uv(ic, jc);
    const cv::Vec3d Ac = cam.to_camera(A), e1 = cam.R * (B - A), e2 = cam.R * (C - A);
    cv::Point2d pa, pb, pc;
    if (!cam.project(A, pa) || !cam.project(B, pb) || !cam.project(C, pc)) return;
    const cv::Vec3d nw = (B - A).cross(C - A);  // into the paper
    const bool front = (cam_centre - A).dot(nw) < 0;
    const double img_area = 0.5 * std::abs((pb - pa).cross(pc - pa));
    if (img_area < 1e-6) return;
    const double tex_area = 0.5 * std::abs((b - a).cross(c - a)) * ppm_ * ppm_;
    const auto& pyr = front ? front_pyr_ : back_pyr_;
    const int level = std::clamp(static_cast<int>(std::floor(0.5 * std::log2(tex_area / img_area))), 0,
                                 static_cast<int>(pyr.size()) - 1);
    const cv::Mat& tex = pyr[static_cast<std::size_t>(level)];
    const double shade = 0.8 + 0.2 * std::abs(cv::normalize(nw).dot(light));
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({pa.x, pb.x, pc.x}))) - 2);
    const int x1 = std::min(cam.width - 1, static_cast<int>(std::ceil(std::max({pa.x, pb.x, pc.x}))) + 2);
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({pa.y, pb.y, pc.y}))) - 2);
    const int y1 = std::min(cam.height - 1, static_cast<int>(std::ceil(std::max({pa.y, pb.y, pc.y}))) + 2);
    if (x0 > x1 || y0 > y1) return;
    const cv::Rect2d box(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
    sheet_box = any ? (sheet_box | box) : box;
    any = true;
    const cv::Vec3d T = -Ac;
    const cv::Vec3d Q = T.cross(e1);
    for (int y = y0; y <= y1; ++y) {
      const auto* ray = rays.ptr<cv::Vec2f>(y);
      float* depth = out.depth.ptr<float>(y);
      float* px = img.ptr<float>(y);
      for (int x = x0; x <= x1; ++x) {
        const cv::Vec3d d(ray[x][0], ray[x][1], 1.0);  // Moller-Trumbore from the camera centre
        const cv::Vec3d P = d.cross(e2);
        const double det = e1.dot(P);
        if (std::abs(det) < 1e-12) continue;
        const double inv = 1.0 / det;
        const double s = T.dot(P) * inv;
        const double r = d.dot(Q) * inv;
        if (s < -1e-9 || r < -1e-9 || s + r > 1 + 1e-9) continue;
        const double z = e2.dot(Q) * inv;
        if (z <= 0 || z >= depth[x]) continue;
        depth[x] = static_cast<float>(z);
        const cv::Point2d uv = a + s * (b - a) + r * (c - a);
        const double tx = (uv.x * ppm_ - 0.5) / (1 << level), ty = (uv.y * ppm_ - 0.5) / (1 << level);
        const float albedo = kPaperBlack + (kPaperWhite - kPaperBlack) * bilinear(tex, tx, ty) / 255.f;
        px[x] = static_cast<float>(albedo * shade);
      }
    }
  };
  for (int j = 0; j + 1 < mesh.ny; ++j)
    for (int i = 0; i + 1 < mesh.nx; ++i) {
      draw_triangle(i, j, i + 1, j, i, j + 1);
      draw_triangle(i + 1, j, i + 1, j + 1, i, j + 1);
    }

  out.occluder_mask = cv::Mat::zeros(cam.height, cam.width, CV_8U);
  if (shapes.empty()) {
    out.shape_depth.release();  // none drawn: no image to fill and read (depth_view.h)
  } else {
    out.shape_depth.create(cam.height, cam.width, CV_32F);
    out.shape_depth.setTo(cv::Scalar(kInf));
    ShapeDrawing drawing;
    drawing.table_z_mm = opt.table_z_mm;
    drawing.lattice_px = opt.shape_lattice_px;
    draw_shapes(cam, rays, ray_bounds_[static_cast<std::size_t>(ci)], shapes, drawing, out.depth,
                img, out.shape_depth, out.occluder_mask);
  }
  if (any && opt.occluders > 0) {
    const cv::Rect region = cv::Rect(sheet_box) & cv::Rect(0, 0, cam.width, cam.height);
    for (int k = 0; k < opt.occluders; ++k) draw_hand(img, out.occluder_mask, rng, region);
  }
  if (opt.blur_sigma_px > 0) cv::GaussianBlur(img, img, cv::Size(), opt.blur_sigma_px);
  if (opt.noise_sigma > 0) {
    cv::Mat noise(img.size(), CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, opt.noise_sigma);
    img = img * opt.exposure + noise;
  } else {
    img = img * opt.exposure;
  }
  img.convertTo(out.image, CV_8U);  // rounds and saturates
}

cv::Mat render_clutter(int width, int height, std::uint64_t seed, int max_layout_id) {
  cv::RNG rng(seed * 2654435761ULL + 99ULL);
  cv::Mat img(height, width, CV_32F);
  draw_background(img, rng, true);
  const auto tags = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  const auto other = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  for (int k = 0; k < 12; ++k) {
    const int side = rng.uniform(30, 120);
    const int x = rng.uniform(0, width - side), y = rng.uniform(0, height - side);
    cv::Mat patch;
    switch (k % 4) {
      case 0: {  // an AprilTag id outside the layout
        const int id = rng.uniform(max_layout_id + 1, tags->bytesList.rows);
        cv::aruco::drawMarker(tags, id, side, patch, 1);
        break;
      }
      case 1:
        cv::aruco::drawMarker(other, rng.uniform(0, 50), side, patch, 1);
        break;
      case 2: {  // random 6x6 bits with a black border
        cv::Mat bits(8, 8, CV_8U, cv::Scalar(0));
        cv::Mat inner = bits(cv::Rect(1, 1, 6, 6));
        rng.fill(inner, cv::RNG::UNIFORM, 0, 2);
        inner *= 255;
        cv::resize(bits, patch, cv::Size(side, side), 0, 0, cv::INTER_NEAREST);
        break;
      }
      default: {  // checkerboard
        patch.create(side, side, CV_8U);
        const int cell = std::max(3, side / rng.uniform(3, 9));
        for (int r = 0; r < side; ++r)
          for (int c = 0; c < side; ++c) patch.at<uchar>(r, c) = ((r / cell + c / cell) % 2) ? 255 : 0;
      }
    }
    cv::Mat quiet(side + side / 4, side + side / 4, CV_8U, cv::Scalar(255));
    patch.copyTo(quiet(cv::Rect(side / 8, side / 8, side, side)));
    // A random perspective tilt.
    const float s = static_cast<float>(quiet.cols);
    const cv::Point2f src[4] = {{0, 0}, {s, 0}, {s, s}, {0, s}};
    cv::Point2f dst[4];
    for (int q = 0; q < 4; ++q)
      dst[q] = src[q] + cv::Point2f(static_cast<float>(rng.uniform(-0.12, 0.12) * s),
                                    static_cast<float>(rng.uniform(-0.12, 0.12) * s));
    cv::Mat warped, wmask;
    const cv::Size box(static_cast<int>(s * 1.3), static_cast<int>(s * 1.3));
    if (x + box.width >= width || y + box.height >= height) continue;
    cv::Mat quiet_f;
    quiet.convertTo(quiet_f, CV_32F, 0.8, 25);
    const cv::Mat H = cv::getPerspectiveTransform(src, dst);
    cv::warpPerspective(quiet_f, warped, H, box, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(-1));
    cv::Mat roi = img(cv::Rect(x, y, box.width, box.height));
    warped.copyTo(roi, warped >= 0);
  }
  for (int k = 0; k < 6; ++k)
    cv::putText(img, "Crease 36h11 #" + std::to_string(rng.uniform(0, 1000)),
                cv::Point(rng.uniform(0, width - 200), rng.uniform(20, height)), cv::FONT_HERSHEY_SIMPLEX,
                rng.uniform(0.5, 1.5), cv::Scalar(rng.uniform(0, 255)), 2, cv::LINE_AA);
  cv::GaussianBlur(img, img, cv::Size(), 0.6);
  cv::Mat noise(img.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
  img += noise;
  cv::Mat out;
  img.convertTo(out, CV_8U);
  return out;
}

}  // namespace crease::vision
