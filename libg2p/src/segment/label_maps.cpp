// Label maps as images a person can read (colours and a legend) and as files
// a program can read (class-index PNG, probabilities as .npy).
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/file_util.h"
#include "core/json_text.h"
#include "core/parallel.h"
#include "g2p/io.h"
#include "g2p/render.h"
#include "g2p/segment.h"

namespace g2p {
namespace {

std::string view_name(std::size_t index, const char* what, const char* ext) {
  char name[64];
  std::snprintf(name, sizeof(name), "view_%02zu_%s.%s", index, what, ext);
  return name;
}

cv::Mat as_mat(ImageU8& image) { return cv::Mat(image.height(), image.width(), CV_8UC3, image.data()); }

}  // namespace

ImageU8 colorize_labels(const ImageI32& labels, const MaterialTable& table,
                        const std::array<std::uint8_t, 3>& background) {
  ImageU8 out(labels.width(), labels.height(), 3);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const int l = labels.data()[i];
    const std::array<std::uint8_t, 3>& c = table.valid_label(l) ? table[l].color : background;
    std::memcpy(out.data() + 3 * i, c.data(), 3);
  }
  return out;
}

ImageU8 label_legend(const MaterialTable& table, int width) {
  const int row = 22;
  ImageU8 out(std::max(width, 80), row * table.size() + 8, 3);
  cv::Mat m = as_mat(out);
  m.setTo(cv::Scalar(255, 255, 255));
  for (int c = 0; c < table.size(); ++c) {
    const auto& col = table[c].color;
    const int y = 4 + c * row;
    cv::rectangle(m, cv::Rect(6, y + 2, 28, row - 6), cv::Scalar(col[0], col[1], col[2]), cv::FILLED);
    cv::rectangle(m, cv::Rect(6, y + 2, 28, row - 6), cv::Scalar(0, 0, 0), 1);
    cv::putText(m, std::to_string(c) + " " + table[c].name, cv::Point(42, y + row - 7), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  return out;
}

Status write_label_maps(const std::string& dir, const std::vector<LabelMap>& maps, const MaterialTable& table) {
  if (maps.empty()) return Status::InvalidArgument("write_label_maps: no label maps");
  G2P_RETURN_IF_ERROR(detail::ensure_directory(dir));
  const std::string base = dir + "/";
  ImageU8 legend = label_legend(table);
  std::vector<ImageU8> coloured(maps.size());
  // The views are encoded and written side by side (PNG encoding is most of the time).
  const Status written = detail::parallel_each(maps.size(), [&](std::size_t i) -> Status {
    const LabelMap& map = maps[i];
    // Colour-coded labels with the legend on the right.
    ImageU8& colours = coloured[i] = colorize_labels(map.labels, table);
    ImageU8 sheet(colours.width() + legend.width(), std::max(colours.height(), legend.height()), 3);
    cv::Mat s = as_mat(sheet);
    s.setTo(cv::Scalar(255, 255, 255));
    as_mat(colours).copyTo(s(cv::Rect(0, 0, colours.width(), colours.height())));
    as_mat(legend).copyTo(s(cv::Rect(colours.width(), 0, legend.width(), legend.height())));
    G2P_RETURN_IF_ERROR(write_image(base + view_name(i, "labels", "png"), sheet));
    // Class indices for programs: 255 = unknown.
    ImageU8 index(map.labels.width(), map.labels.height(), 1);
    for (std::size_t k = 0; k < map.labels.size(); ++k) {
      const int l = map.labels.data()[k];
      index.data()[k] = l >= 0 && l < 255 ? static_cast<std::uint8_t>(l) : 255;
    }
    G2P_RETURN_IF_ERROR(write_image(base + view_name(i, "labels_index", "png"), index));
    if (!map.probabilities.empty())
      return detail::write_file_atomically(base + view_name(i, "probs", "npy"), detail::npy_float32(map.probabilities));
    return Status::Ok();
  });
  if (!written.ok()) return written;
  G2P_RETURN_IF_ERROR(write_image(base + "legend.png", legend));
  // All views at a glance, the legend as the last tile.
  std::vector<const ImageU8*> tiles;
  for (const ImageU8& c : coloured) tiles.push_back(&c);
  ImageU8 legend_tile = legend;
  tiles.push_back(&legend_tile);
  G2P_RETURN_IF_ERROR(
      write_image(base + "contact_sheet.png", contact_sheet(tiles, 4, 256, static_cast<int>(coloured.size()))));
  nlohmann::json classes = nlohmann::json::array();
  for (int c = 0; c < table.size(); ++c)
    classes.push_back({{"index", c}, {"name", table[c].name}, {"color", table[c].color}});
  const nlohmann::json doc = {{"table", table.name()}, {"unknown_index", 255}, {"classes", classes}};
  return detail::write_file_atomically(base + "classes.json", detail::json_text(doc, 2) + "\n");
}

}  // namespace g2p
