// Per-region features: what the classifier sees of a region.
//
// Votes are each face's vote histogram made into shares (so hard and soft
// votes, and any number of views, give the same scale), weighted by the
// face's area; unseen faces add nothing. Colours are linear RGB shown as
// sRGB-like values (gamma 1/2.2) and as hue (a unit vector scaled by the
// saturation, so greys have no hue), saturation and value. Geometry is in
// libg2p's frame (+Z up) and relative to the object's bounds, so that a
// normalised generator mesh and a metric catalogue model give the same values.
#include <algorithm>
#include <cmath>

#include "g2p/regions.h"

namespace g2p {
namespace {

const char* const kTail[] = {
    "log_area_share",  // log10 of the region's share of the surface
    "seen_share",      // share of the region's area some view saw
    "r",               // mean colour, gamma 1/2.2
    "g",
    "b",
    "hue_x",  // saturation * cos(hue)
    "hue_y",  // saturation * sin(hue)
    "saturation",
    "value",
    "colour_spread",    // area-weighted standard deviation of the face colours (linear RGB)
    "colour_contrast",  // distance from the object's mean colour (linear RGB)
    "height",           // centroid height in the object's bounds, 0 (bottom) to 1 (top)
    "radial",           // centroid distance from the object's vertical axis over the half horizontal diagonal
    "extent_1",         // the region's bounds, sides sorted longest first, over the object's diagonal
    "extent_2",
    "extent_3",
    "up_facing",      // area-weighted mean |normal . up|
    "log_regions",    // log10 of the object's region count
    "object_height",  // the object's height over its diagonal
};
constexpr int kTailCount = static_cast<int>(sizeof(kTail) / sizeof(kTail[0]));

}  // namespace

std::vector<std::string> region_feature_names(const MaterialTable& table) {
  std::vector<std::string> names;
  for (const MaterialClass& c : table.classes()) names.push_back("vote_" + c.name);
  for (const MaterialClass& c : table.classes()) names.push_back("object_vote_" + c.name);
  names.insert(names.end(), kTail, kTail + kTailCount);
  return names;
}

Result<std::vector<float>> region_features(const Mesh& mesh, const Regions& regions, const FaceVotes& votes,
                                           const FaceColours& colours, const MaterialTable& table) {
  const int nf = mesh.num_faces(), k = table.size();
  if (static_cast<int>(regions.face_region.size()) != nf || static_cast<int>(votes.total.size()) != nf ||
      static_cast<int>(votes.row.size()) != nf || static_cast<int>(colours.rgb.size()) != nf ||
      static_cast<int>(colours.pixels.size()) != nf || votes.num_classes != k)
    return Status::InvalidArgument("region_features: regions, votes or colours are not of this mesh and table");
  for (int f = 0; f < nf; ++f) {
    const int row = votes.row[static_cast<std::size_t>(f)];
    if (row >= 0 && (static_cast<std::size_t>(row) + 1) * static_cast<std::size_t>(k) > votes.histogram.size())
      return Status::InvalidArgument("region_features: face " + std::to_string(f) + "'s votes are out of range");
  }
  for (const Region& region : regions.regions)
    for (const int f : region.faces)
      if (f < 0 || f >= nf)
        return Status::InvalidArgument("region_features: a region names face " + std::to_string(f) + " of " +
                                       std::to_string(nf));
  const int width = 2 * k + kTailCount;
  const std::size_t nr = regions.regions.size();
  std::vector<float> out(nr * static_cast<std::size_t>(width), 0.f);

  const Eigen::AlignedBox3d box = bounds(mesh);
  const Eigen::Vector3d size = box.isEmpty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(box.sizes());
  const double diagonal = std::max(size.norm(), 1e-12);
  const double half_horizontal = std::max(0.5 * std::hypot(size.x(), size.y()), 1e-12);
  const Eigen::Vector3d centre = box.isEmpty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(box.center());

  double total_area = 0.0;
  std::vector<double> object_votes(static_cast<std::size_t>(k), 0.0);
  Eigen::Vector3d object_colour = Eigen::Vector3d::Zero();
  double object_colour_area = 0.0;
  std::vector<double> area(static_cast<std::size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    const double a = area[static_cast<std::size_t>(f)] = face_area(mesh, f);
    total_area += a;
    const float* h = votes.of(f);
    const float t = votes.total[static_cast<std::size_t>(f)];
    if (h != nullptr && t > 0.f)
      for (int c = 0; c < k; ++c) object_votes[static_cast<std::size_t>(c)] += a * h[c] / t;
    if (colours.pixels[static_cast<std::size_t>(f)] > 0.f) {
      object_colour += a * colours.rgb[static_cast<std::size_t>(f)].cast<double>();
      object_colour_area += a;
    }
  }
  double object_vote_sum = 0.0;
  for (double v : object_votes) object_vote_sum += v;
  if (object_colour_area > 0.0) object_colour /= object_colour_area;

  for (std::size_t r = 0; r < nr; ++r) {
    const Region& region = regions.regions[r];
    float* row = out.data() + r * static_cast<std::size_t>(width);
    double region_area = 0.0, seen_area = 0.0, voted_area = 0.0, colour_area = 0.0, up = 0.0;
    std::vector<double> v(static_cast<std::size_t>(k), 0.0);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero(), square = Eigen::Vector3d::Zero(),
                    centroid = Eigen::Vector3d::Zero();
    Eigen::AlignedBox3d region_box;
    for (const int f : region.faces) {
      const double a = area[static_cast<std::size_t>(f)];
      region_area += a;
      const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(f)];
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d p = mesh.positions[static_cast<std::size_t>(t[i])].cast<double>();
        region_box.extend(p);
        c += p / 3.0;
      }
      centroid += a * c;
      up += a * std::abs(face_normal(mesh, f).z());
      const float* h = votes.of(f);
      const float total = votes.total[static_cast<std::size_t>(f)];
      if (h != nullptr && total > 0.f) {
        voted_area += a;
        for (int cl = 0; cl < k; ++cl) v[static_cast<std::size_t>(cl)] += a * h[cl] / total;
      }
      if (colours.pixels[static_cast<std::size_t>(f)] > 0.f) {
        seen_area += a;
        colour_area += a;
        const Eigen::Vector3d rgb = colours.rgb[static_cast<std::size_t>(f)].cast<double>();
        mean += a * rgb;
        square += a * rgb.cwiseProduct(rgb);
      }
    }
    int col = 0;
    for (int cl = 0; cl < k; ++cl)
      row[col++] = voted_area > 0.0 ? static_cast<float>(v[static_cast<std::size_t>(cl)] / voted_area) : 0.f;
    for (int cl = 0; cl < k; ++cl)
      row[col++] = object_vote_sum > 0.0
                       ? static_cast<float>(object_votes[static_cast<std::size_t>(cl)] / object_vote_sum)
                       : 0.f;
    const double share = total_area > 0.0 ? region_area / total_area : 0.0;
    row[col++] = static_cast<float>(std::log10(std::max(share, 1e-9)));
    row[col++] = region_area > 0.0 ? static_cast<float>(seen_area / region_area) : 0.f;
    double spread = 0.0;
    if (colour_area > 0.0) {
      mean /= colour_area;
      const Eigen::Vector3d variance = (square / colour_area - mean.cwiseProduct(mean)).cwiseMax(0.0);
      spread = std::sqrt(variance.sum());
    }
    Eigen::Vector3d gamma;
    for (int i = 0; i < 3; ++i) gamma[i] = std::pow(std::clamp(mean[i], 0.0, 1.0), 1.0 / 2.2);
    for (int i = 0; i < 3; ++i) row[col++] = static_cast<float>(gamma[i]);
    // HSV of the gamma colour.
    const double mx = gamma.maxCoeff(), mn = gamma.minCoeff(), chroma = mx - mn;
    double hue = 0.0;
    if (chroma > 1e-9) {
      if (mx == gamma[0])
        hue = std::fmod((gamma[1] - gamma[2]) / chroma + 6.0, 6.0);
      else if (mx == gamma[1])
        hue = (gamma[2] - gamma[0]) / chroma + 2.0;
      else
        hue = (gamma[0] - gamma[1]) / chroma + 4.0;
    }
    const double saturation = mx > 1e-9 ? chroma / mx : 0.0, angle = hue * M_PI / 3.0;
    row[col++] = static_cast<float>(saturation * std::cos(angle));
    row[col++] = static_cast<float>(saturation * std::sin(angle));
    row[col++] = static_cast<float>(saturation);
    row[col++] = static_cast<float>(mx);
    row[col++] = static_cast<float>(spread);
    row[col++] =
        colour_area > 0.0 && object_colour_area > 0.0 ? static_cast<float>((mean - object_colour).norm()) : 0.f;
    if (region_area > 0.0) centroid /= region_area;
    row[col++] = size.z() > 0.0 ? static_cast<float>((centroid.z() - box.min().z()) / size.z()) : 0.5f;
    row[col++] = static_cast<float>(std::hypot(centroid.x() - centre.x(), centroid.y() - centre.y()) / half_horizontal);
    Eigen::Vector3d extent = region_box.isEmpty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(region_box.sizes());
    std::sort(extent.data(), extent.data() + 3, [](double a, double b) { return a > b; });
    for (int i = 0; i < 3; ++i) row[col++] = static_cast<float>(extent[i] / diagonal);
    row[col++] = region_area > 0.0 ? static_cast<float>(up / region_area) : 0.f;
    row[col++] = static_cast<float>(std::log10(static_cast<double>(std::max<std::size_t>(nr, 1))));
    row[col++] = static_cast<float>(size.z() / diagonal);
  }
  return out;
}

}  // namespace g2p
