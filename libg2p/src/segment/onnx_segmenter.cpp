// The `onnx` segmenter: any semantic-segmentation network exported to ONNX,
// run with OpenCV's dnn module (CPU). A JSON model card says how to feed it
// and how its output classes map onto the vocabulary (docs/segment.md):
//
//   {"format": "g2p-onnx-model-card", "version": 1,
//    "model": "net.onnx",                       // relative to the card
//    "input": {"width": 512, "height": 512, "channel_order": "RGB",
//              "scale": 0.00392156862745098, "mean": [0.485, 0.456, 0.406],
//              "std": [0.229, 0.224, 0.225], "name": "pixel_values",
//              "channels": ["rgb"]},               // optional; or ["rgb", "normal"]
//    "output": {"kind": "logits", "name": "logits"},   // or "probabilities"
//    "classes": ["background", "Wood", "Metal", ...]}  // per output channel
//
// The view's RGB is resized to the input size, each channel becomes
// (value * scale - mean) / std. input.channels lists the buffers the network
// takes, in order: "rgb" (3 channels, as above) and "normal" (3 channels: the
// view's unit normal in its camera's frame, x right, y down, z away from the
// viewer; 0 on the background, and 0 everywhere when the view was rendered
// without geometry buffers, which networks trained with normal dropout
// tolerate). The NCHW output is resized back to the
// view (bilinear), turned into probabilities (softmax for logits) and summed
// per vocabulary class. Channels named "background", "ignore" or with no
// class in the table are dropped; on object pixels the rest are renormalised,
// background pixels (face ID -1) stay unknown.
//
// Settings: model_card = path of the card (required); flip = off (default)
// or on: test-time augmentation, the network also sees the view mirrored
// left to right (normals mirrored with it: their x negated), its output is
// mirrored back, and the two passes' logits (or probabilities) are averaged.
// Averaging logits is the geometric mean of the two passes' probabilities,
// as in the ensembles of tools/training/ensemble.py. Twice the inference time.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "g2p/segment.h"
#include "segment/backends.h"

namespace g2p {
namespace {

using nlohmann::json;

struct ModelCard {
  std::string model_path;
  int width = 0, height = 0;
  bool bgr = false;
  float scale = 1.f / 255.f;
  cv::Scalar mean{0, 0, 0}, std{1, 1, 1};
  std::string input_name, output_name;
  bool logits = true;
  std::vector<std::string> classes;
  std::vector<std::string> channels{"rgb"};  // the input's buffers, in order
};

Result<ModelCard> read_card(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open the model card");
  std::ostringstream text;
  text << in.rdbuf();
  const json doc = json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return Status::ParseError(path + ": not a JSON object");
  if (doc.contains("format") && doc["format"] != "g2p-onnx-model-card")
    return Status::ParseError(path + ": 'format' must be \"g2p-onnx-model-card\"");
  if (doc.contains("version") && (!doc["version"].is_number_integer() || doc["version"].get<int>() < 1))
    return Status::ParseError(path + ": 'version' must be a positive integer");
  if (doc.contains("version") && doc["version"].get<int>() > 1)
    return Status::Unsupported(path + ": model card version " + doc["version"].dump() + " is newer than 1");
  const struct {
    const char* key;
    const char* what;
  } required[] = {{"model", "the .onnx file, relative to the card"},
                  {"input", "the network's input: width, height and normalisation"},
                  {"classes", "the class of each output channel, in order"}};
  for (const auto& r : required)
    if (!doc.contains(r.key))
      return Status::ParseError(path + ": the model card needs '" + r.key + "' (" + r.what + "); docs/segment.md");
  ModelCard card;
  try {
    card.model_path = doc.at("model").get<std::string>();
    if (std::filesystem::path(card.model_path).is_relative())
      card.model_path = (std::filesystem::path(path).parent_path() / card.model_path).string();
    const json& input = doc.at("input");
    for (const char* key : {"width", "height"}) {
      const json& n = input.at(key);
      if (!n.is_number_integer() || n.get<long long>() < 1 || n.get<long long>() > 16384)
        return Status::ParseError(path + ": input." + key + " must be a whole number of pixels from 1 to 16384, not " +
                                  n.dump());
    }
    card.width = input.at("width").get<int>();
    card.height = input.at("height").get<int>();
    const std::string order = input.value("channel_order", "RGB");
    if (order != "RGB" && order != "BGR") return Status::ParseError(path + ": input.channel_order must be RGB or BGR");
    card.bgr = order == "BGR";
    card.scale = input.value("scale", 1.f / 255.f);
    if (input.contains("mean")) {
      const auto m = input.at("mean").get<std::vector<double>>();
      if (m.size() != 3) return Status::ParseError(path + ": input.mean needs 3 values");
      card.mean = cv::Scalar(m[0], m[1], m[2]);
    }
    if (input.contains("std")) {
      const auto s = input.at("std").get<std::vector<double>>();
      if (s.size() != 3 || s[0] <= 0 || s[1] <= 0 || s[2] <= 0)
        return Status::ParseError(path + ": input.std needs 3 positive values");
      card.std = cv::Scalar(s[0], s[1], s[2]);
    }
    card.input_name = input.value("name", "");
    if (input.contains("channels")) {
      card.channels = input.at("channels").get<std::vector<std::string>>();
      if (card.channels.empty()) return Status::ParseError(path + ": input.channels is empty");
      for (std::size_t i = 0; i < card.channels.size(); ++i) {
        if (card.channels[i] != "rgb" && card.channels[i] != "normal")
          return Status::ParseError(path + ": input.channels[" + std::to_string(i) + "] is '" + card.channels[i] +
                                    "'; known: rgb, normal");
        if (std::find(card.channels.begin(), card.channels.begin() + static_cast<long>(i), card.channels[i]) !=
            card.channels.begin() + static_cast<long>(i))
          return Status::ParseError(path + ": input.channels names '" + card.channels[i] + "' twice");
      }
    }
    if (doc.contains("output")) {
      const json& output = doc.at("output");
      const std::string kind = output.value("kind", "logits");
      if (kind != "logits" && kind != "probabilities")
        return Status::ParseError(path + ": output.kind must be logits or probabilities");
      card.logits = kind == "logits";
      card.output_name = output.value("name", "");
    }
    card.classes = doc.at("classes").get<std::vector<std::string>>();
  } catch (const json::exception& e) {
    // "[json.exception.type_error.302] type must be string, but is number":
    // the part after the bracket says what was wrong.
    std::string why = e.what();
    if (const std::size_t end = why.find("] "); why.rfind("[json.exception.", 0) == 0 && end != std::string::npos)
      why = why.substr(end + 2);
    return Status::ParseError(path + ": a value of the wrong kind (" + why + "); docs/segment.md lists the fields");
  }
  if (card.width < 8 || card.height < 8 || card.width > 8192 || card.height > 8192)
    return Status::ParseError(path + ": input size outside 8..8192");
  if (card.classes.empty()) return Status::ParseError(path + ": 'classes' is empty");
  return card;
}

// The view's camera-space normals at the network's input size
// (area-averaged), 3 float channels; zeros where the view has none.
cv::Mat normals_input(const View& view, cv::Size size) {
  ImageF normals = camera_space_normals(view);
  if (normals.empty()) return cv::Mat(size, CV_32FC3, cv::Scalar(0, 0, 0));
  cv::Mat resized;
  cv::resize(cv::Mat(normals.height(), normals.width(), CV_32FC3, normals.data()), resized, size, 0, 0, cv::INTER_AREA);
  return resized;
}

class OnnxSegmenter final : public Segmenter {
 public:
  // `deferred`: configure reads and checks the card, and the network is
  // loaded by the first set_model (see make_deferred_onnx_segmenter).
  explicit OnnxSegmenter(bool deferred = false) : deferred_(deferred) {}

  SettingsSpec settings() override {
    return SettingsSpec("onnx")
        .text("model_card", card_path_, "the network's card (JSON: the ONNX file, input size, classes)")
        .flag("flip", flip_, "also read each view mirrored and average the two")
        .check([this] { return load_card(); });
  }

  Status set_model(const Model&, const MaterialTable& table) override {
    if (card_.classes.empty()) return Status::InvalidArgument("onnx: needs the setting model_card=CARD.json");
    if (net_.empty()) G2P_RETURN_IF_ERROR(load_network());
    num_classes_ = table.size();
    channel_class_.clear();
    bool any = false;
    for (const std::string& name : card_.classes) {
      channel_class_.push_back(name == "background" || name == "ignore" ? kUnknownLabel : table.find(name));
      any |= channel_class_.back() != kUnknownLabel;
    }
    if (!any) return Status::InvalidArgument("onnx: no output class of the model card is in the material table");
    return Status::Ok();
  }

  Status segment_into(const View& view, LabelMap& out) const override {
    if (channel_class_.empty()) return Status::InvalidArgument("onnx: set_model() first");
    const int w = view.face_id.width(), h = view.face_id.height();
    const bool needs_rgb = std::find(card_.channels.begin(), card_.channels.end(), "rgb") != card_.channels.end();
    if (needs_rgb && (view.rgb.width() != w || view.rgb.height() != h || view.rgb.channels() != 3))
      return Status::InvalidArgument("onnx: the view needs an RGB image (render with shading on)");
    if (!needs_rgb && view.normal.empty())  // zeros would be all the network sees
      return Status::InvalidArgument(
          "onnx: the model card takes normals only and the view has none (render with "
          "geometry buffers on)");

    const cv::Size size(card_.width, card_.height);
    std::vector<cv::Mat> inputs;  // one 3-channel float image per entry of card_.channels
    for (const std::string& channel : card_.channels) {
      if (channel == "normal") {
        inputs.push_back(normals_input(view, size));
        continue;
      }
      cv::Mat rgb(h, w, CV_8UC3, const_cast<std::uint8_t*>(view.rgb.data()));
      cv::Mat input;
      cv::resize(rgb, input, size, 0, 0, cv::INTER_AREA);
      if (card_.bgr) cv::cvtColor(input, input, cv::COLOR_RGB2BGR);
      input.convertTo(input, CV_32FC3, card_.scale);
      inputs.push_back((input - card_.mean) / card_.std);
    }
    cv::Mat output;
    try {
      // NCHW: the planes of every input, in the card's order.
      const int sizes[4] = {1, 3 * static_cast<int>(inputs.size()), size.height, size.width};
      cv::Mat blob(4, sizes, CV_32F);
      for (std::size_t i = 0; i < inputs.size(); ++i) {
        cv::Mat planes[3];
        for (int c = 0; c < 3; ++c) planes[c] = cv::Mat(size, CV_32F, blob.ptr<float>(0, 3 * static_cast<int>(i) + c));
        const int from_to[] = {0, 0, 1, 1, 2, 2};
        cv::mixChannels(&inputs[i], 1, planes, 3, from_to, 3);  // writes into the blob's memory
      }
      std::lock_guard<std::mutex> lock(mutex_);  // cv::dnn::Net::forward is not const
      net_.setInput(blob, card_.input_name);
      output = net_.forward(card_.output_name).clone();
      if (flip_) {
        cv::Mat mirrored(4, sizes, CV_32F);
        for (int c = 0; c < sizes[1]; ++c) {
          const cv::Mat from(size, CV_32F, blob.ptr<float>(0, c));
          cv::Mat to(size, CV_32F, mirrored.ptr<float>(0, c));
          cv::flip(from, to, 1);
          if (card_.channels[static_cast<std::size_t>(c / 3)] == "normal" && c % 3 == 0)
            to.convertTo(to, -1, -1.0);  // the normal's x (right) turns with the view
        }
        net_.setInput(mirrored, card_.input_name);
        const cv::Mat second = net_.forward(card_.output_name);
        if (second.dims != 4 || !std::equal(second.size.p, second.size.p + 4, output.size.p))
          return Status::Internal("onnx: the mirrored view's output has another shape than the view's");
        for (int c = 0; c < output.size[1]; ++c) {
          cv::Mat sum(output.size[2], output.size[3], CV_32F, output.ptr<float>(0, c)), back;
          cv::flip(cv::Mat(output.size[2], output.size[3], CV_32F, const_cast<float*>(second.ptr<float>(0, c))), back,
                   1);
          cv::addWeighted(sum, 0.5, back, 0.5, 0.0, sum);
        }
      }
    } catch (const cv::Exception& e) {
      return Status::Internal(std::string("onnx: inference failed: ") + e.what());
    }
    if (output.dims != 4 || output.size[0] != 1 || output.size[1] != static_cast<int>(channel_class_.size()))
      return Status::InvalidArgument("onnx: the network's output is not 1 x " + std::to_string(channel_class_.size()) +
                                     " x H x W as the model card's classes say");
    const int channels = output.size[1], oh = output.size[2], ow = output.size[3];

    // Per output channel, resized to the view.
    std::vector<cv::Mat> planes(static_cast<std::size_t>(channels));
    for (int c = 0; c < channels; ++c) {
      const cv::Mat plane(oh, ow, CV_32F, output.ptr<float>(0, c));
      cv::resize(plane, planes[static_cast<std::size_t>(c)], cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
    }
    out.labels.reset(w, h, 1, kUnknownLabel);
    out.probabilities.reset(w, h, num_classes_, 0.f);
    std::vector<float> p(static_cast<std::size_t>(channels));
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (view.face_id.at(x, y) < 0) continue;
        float mx = -1e30f;
        for (int c = 0; c < channels; ++c) mx = std::max(mx, p[c] = planes[c].at<float>(y, x));
        if (card_.logits) {
          for (int c = 0; c < channels; ++c) p[c] = std::exp(p[c] - mx);
        }
        float* q = out.probabilities.pixel(x, y);
        float sum = 0.f;
        for (int c = 0; c < channels; ++c) {
          if (channel_class_[c] == kUnknownLabel) continue;
          q[channel_class_[c]] += std::max(p[c], 0.f);
          sum += std::max(p[c], 0.f);
        }
        if (!(sum > 0.f)) continue;
        int best = 0;
        for (int c = 0; c < num_classes_; ++c) {
          q[c] /= sum;
          if (q[c] > q[best]) best = c;
        }
        out.labels.at(x, y) = best;
      }
    }
    return Status::Ok();
  }

 private:
  // The card named by model_card, and its network unless deferred; the
  // backend keeps its old card when either cannot be read.
  Status load_card() {
    if (card_path_ == loaded_card_) return Status::Ok();
    Result<ModelCard> card = read_card(card_path_);
    if (!card.ok()) return card.status();
    if (deferred_) {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(card->model_path, ec))
        return Status::NotFound(card->model_path + ": the model card's network file is missing");
    }
    ModelCard old = std::move(card_);
    card_ = std::move(*card);
    net_ = cv::dnn::Net();
    if (!deferred_) {
      if (Status s = load_network(); !s.ok()) {
        card_ = std::move(old);
        return s;
      }
    }
    loaded_card_ = card_path_;
    return Status::Ok();
  }

  // Reads card_.model_path into net_ (OpenCV's dnn module, on the CPU).
  Status load_network() {
    try {
      net_ = cv::dnn::readNetFromONNX(card_.model_path);
    } catch (const cv::Exception& e) {
      net_ = cv::dnn::Net();
      return Status::ParseError(card_.model_path + ": OpenCV cannot load the ONNX model: " + e.what());
    }
    if (net_.empty()) return Status::ParseError(card_.model_path + ": OpenCV loaded an empty network");
    net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
    net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    return Status::Ok();
  }

  bool deferred_ = false;
  std::string card_path_, loaded_card_;  // model_card, and the card card_ holds
  ModelCard card_;
  bool flip_ = false;  // test-time mirroring (setting flip)
  mutable cv::dnn::Net net_;
  mutable std::mutex mutex_;
  int num_classes_ = 0;
  std::vector<int> channel_class_;  // per output channel: table class or kUnknownLabel
};

}  // namespace

std::unique_ptr<Segmenter> make_onnx_segmenter() { return std::make_unique<OnnxSegmenter>(); }
std::unique_ptr<Segmenter> detail::make_deferred_onnx_segmenter() { return std::make_unique<OnnxSegmenter>(true); }

}  // namespace g2p
