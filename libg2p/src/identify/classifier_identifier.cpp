// The "classifier" identifier: an image classifier run on views of the
// object, its classes mapped to the object table's kinds. By default the
// shipped kind classifier (g2p-kinds.json and the files it names: a network
// trained here on rendered furniture libraries, docs/kind-classifier.md);
// else any ONNX image classifier the user points it at (an ImageNet network,
// a domain model: `--identify-set model=PATH labels=PATH`, classes mapped
// through WordNet). With `auto` it votes beside the names and the detector
// (`--identify-set classifier=off` leaves it out).
//
// The labels file names the network's classes in output order: a JSON array
// of strings or one line each. A class is a WordNet 3.0 noun id ("n03376595",
// as ImageNet writes them), words ("folding chair, folding stool": synonyms
// split at commas), or both ("n03376595 folding chair"). An id maps through
// the shipped synsets by kind (wordnet_kinds.json: every synset under a
// kind's); words map where one of them is exactly a term of the object table
// (the table's terms are the lemmas under each kind, so both ways follow
// WordNet's hierarchy). A network with one score more than there are labels
// has a leading background class (TensorFlow's ImageNet models), left out.
//
// Per view the scores become probabilities (a softmax, unless they already
// are) and a kind's probability is the sum over its classes; a kind's
// confidence is the mean over the views, mapped by the shipped card's
// calibration (Platt scaling fitted when it was trained) where it has one.
// The shipped card may also carry a shape head: a small network over the
// mesh's shape_cues() whose class probabilities join the views' ones as
// p(views) * p(shape)^weight, renormalised, before the calibration. The views are the detector's: eight
// of its own at eye level with a renderer, else those given; each is cropped
// to a square about the object's pixels (photographs are framed on the
// object) on a plain grey, then scaled to the network's input.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "core/ascii.h"
#include "core/model_files.h"
#include "core/settings.h"
#include "identify/backends.h"

namespace g2p {
namespace {

// How a network expects its pixels.
enum class Normalization {
  kMinusOneToOne,  // (x - 127.5) / 127.5: TensorFlow and Keras MobileNets
  kImageNet,       // (x / 255 - mean) / std with ImageNet's mean and std: torchvision
  kZeroToOne,      // x / 255
};

std::string trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

// One class of the network as its labels file names it.
struct ClassLabel {
  std::string text;  // as written, for notes ("folding chair")
  long offset = -1;  // its WordNet 3.0 noun offset, -1 = none given
  std::vector<std::string> words;
};

ClassLabel parse_label(const std::string& raw) {
  ClassLabel l;
  std::string rest = trim(raw);
  // "n03376595", optionally followed by words.
  if (rest.size() >= 9 && rest[0] == 'n' &&
      std::all_of(rest.begin() + 1, rest.begin() + 9,
                  [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }) &&
      (rest.size() == 9 || !std::isalnum(static_cast<unsigned char>(rest[9])))) {
    l.offset = std::stol(rest.substr(1, 8));
    rest = trim(rest.substr(9));
    while (!rest.empty() && (rest[0] == ',' || rest[0] == ':' || rest[0] == ';')) rest = trim(rest.substr(1));
  }
  std::stringstream ss(rest);
  std::string word;
  while (std::getline(ss, word, ','))
    if (!trim(word).empty()) l.words.push_back(trim(word));
  l.text = l.words.empty() ? trim(raw) : l.words.front();
  return l;
}

Result<std::vector<ClassLabel>> read_labels(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound("labels=" + path + ": cannot open it");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  std::vector<std::string> raw;
  if (!trim(text).empty() && trim(text)[0] == '[') {
    const nlohmann::json doc = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded() || !doc.is_array())
      return Status::ParseError("labels=" + path + ": starts with '[' but is not a JSON array");
    for (std::size_t i = 0; i < doc.size(); ++i) {
      if (!doc[i].is_string())
        return Status::ParseError("labels=" + path + ": entry " + std::to_string(i) + " is not a string");
      raw.push_back(doc[i].get<std::string>());
    }
  } else {
    std::stringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) raw.push_back(line);
    while (!raw.empty() && trim(raw.back()).empty()) raw.pop_back();
  }
  if (raw.empty()) return Status::ParseError("labels=" + path + ": names no class");
  std::vector<ClassLabel> labels;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (trim(raw[i]).empty())
      return Status::ParseError("labels=" + path + ": class " + std::to_string(i + 1) +
                                " is blank (one class a line, in the network's output order)");
    labels.push_back(parse_label(raw[i]));
  }
  return labels;
}

// The kind a class names in `table`, or -1.
int kind_of(const ClassLabel& l, const ObjectTable& table) {
  if (l.offset >= 0) {
    const std::string& name = detail::shipped_wordnet_kind(l.offset);
    if (!name.empty()) {
      const int k = table.find(name);
      if (k >= 0) return k;
    }
  }
  for (const std::string& w : l.words) {
    const std::string want = detail::lower_case(w);
    for (const TextMatch& m : table.match(w))
      if (m.term == want) return m.kind;  // the whole label, not a word inside it ("tiger" of "tiger shark")
  }
  return -1;
}

constexpr const char* kShippedCard = "g2p-kinds.json";

// The card's shape head (train_kinds.py's ShapeHead): standardised
// shape_cues() through dense layers to one logit per class, the network's
// classes in its output order.
struct ShapeHead {
  struct Layer {
    int inputs = 0, outputs = 0;
    std::vector<double> weights, bias;  // weights: outputs x inputs, row-major
    bool tanh = false;
  };
  std::vector<double> mean, scale;
  std::vector<Layer> layers;
  double weight = 0.0;  // the exponent of p(shape) in the join

  bool empty() const { return layers.empty(); }
  int classes() const { return layers.empty() ? 0 : layers.back().outputs; }

  // log p(class | shape) for cues of shape_cue_names().
  std::vector<double> log_probabilities(const std::vector<double>& cues) const {
    std::vector<double> z(cues.size());
    for (std::size_t i = 0; i < cues.size(); ++i) z[i] = (cues[i] - mean[i]) / scale[i];
    for (const Layer& l : layers) {
      std::vector<double> out(l.bias);
      for (int o = 0; o < l.outputs; ++o)
        for (int i = 0; i < l.inputs; ++i) out[o] += l.weights[static_cast<std::size_t>(o) * l.inputs + i] * z[i];
      if (l.tanh)
        for (double& v : out) v = std::tanh(v);
      z = std::move(out);
    }
    const double top = *std::max_element(z.begin(), z.end());
    double sum = 0.0;
    for (double v : z) sum += std::exp(v - top);
    for (double& v : z) v -= top + std::log(sum);
    return z;
  }
};

// The card's "shape" (null or absent: none), checked against this build's cues.
Status read_shape_head(const nlohmann::json& j, ShapeHead& head) {
  if (j.is_null()) return Status::Ok();
  const std::vector<std::string>& names = shape_cue_names();
  if (j.at("cues").get<std::vector<std::string>>() != names)
    return Status::InvalidArgument("shape.cues are not this libg2p's shape_cue_names()");
  head.mean = j.at("mean").get<std::vector<double>>();
  head.scale = j.at("scale").get<std::vector<double>>();
  head.weight = j.at("weight").get<double>();
  if (head.mean.size() != names.size() || head.scale.size() != names.size())
    return Status::InvalidArgument("shape.mean and shape.scale need one number per cue");
  for (double v : head.scale)
    if (!(v > 0) || !std::isfinite(v)) return Status::InvalidArgument("shape.scale must be positive");
  if (!(head.weight >= 0) || !std::isfinite(head.weight))
    return Status::InvalidArgument("shape.weight must be a finite number >= 0");
  int inputs = static_cast<int>(names.size());
  for (const nlohmann::json& lj : j.at("layers")) {
    ShapeHead::Layer l;
    const auto rows = lj.at("weights").get<std::vector<std::vector<double>>>();
    l.bias = lj.at("bias").get<std::vector<double>>();
    l.inputs = inputs, l.outputs = static_cast<int>(rows.size());
    const std::string activation = lj.at("activation").get<std::string>();
    if (activation != "tanh" && activation != "none")
      return Status::InvalidArgument("shape.layers: activation '" + activation + "' is not tanh or none");
    l.tanh = activation == "tanh";
    if (l.outputs == 0 || l.bias.size() != rows.size())
      return Status::InvalidArgument("shape.layers: bias and weights disagree on the outputs");
    for (const std::vector<double>& row : rows) {
      if (static_cast<int>(row.size()) != inputs)
        return Status::InvalidArgument("shape.layers: a layer's weights do not take the previous layer's outputs");
      l.weights.insert(l.weights.end(), row.begin(), row.end());
    }
    for (double v : l.weights)
      if (!std::isfinite(v)) return Status::InvalidArgument("shape.layers: weights must be finite");
    inputs = l.outputs;
    head.layers.push_back(std::move(l));
  }
  if (head.layers.empty()) return Status::InvalidArgument("shape.layers is empty");
  if (head.layers.back().tanh) return Status::InvalidArgument("shape.layers: the last layer gives logits (none)");
  return Status::Ok();
}

// What the shipped card says of its network (tools/training/train_kinds.py
// writes it): the files, relative to the card, and the input.
struct ClassifierCard {
  std::string model, labels;
  int size = 224;
  Normalization normalization = Normalization::kMinusOneToOne;
  bool rgb = true;
  double platt_a = 1.0, platt_b = 0.0;  // confidence = sigmoid(a logit(p) + b); 1, 0 = p itself
  ShapeHead shape;                      // empty: the views alone
};

Result<ClassifierCard> read_card(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open the kind classifier's card");
  std::stringstream ss;
  ss << in.rdbuf();
  const nlohmann::json doc = nlohmann::json::parse(ss.str(), nullptr, /*allow_exceptions=*/false);
  auto bad = [&](const std::string& what) { return Status::ParseError(path + ": " + what); };
  if (doc.is_discarded() || !doc.is_object()) return bad("not valid JSON");
  ClassifierCard c;
  try {
    if (doc.value("format", std::string()) != "g2p-kind-classifier-card" || doc.value("version", 0) != 1)
      return bad("'format' must be \"g2p-kind-classifier-card\", 'version' 1");
    const std::string dir = path.substr(0, path.find_last_of('/') + 1);
    c.model = dir + doc.at("model").get<std::string>();
    c.labels = dir + doc.at("labels").get<std::string>();
    const nlohmann::json& input = doc.at("input");
    c.size = input.at("shape").at(2).get<int>();
    if (input.at("shape").at(3).get<int>() != c.size) return bad("input.shape must be square");
    const std::string norm = input.at("normalization").get<std::string>();
    if (norm == "minus-one-to-one") {
      c.normalization = Normalization::kMinusOneToOne;
    } else if (norm == "imagenet") {
      c.normalization = Normalization::kImageNet;
    } else if (norm == "zero-to-one") {
      c.normalization = Normalization::kZeroToOne;
    } else {
      return bad("input.normalization '" + norm + "' is not minus-one-to-one, imagenet or zero-to-one");
    }
    c.rgb = input.value("channel_order", std::string("RGB")) == "RGB";
    if (doc.contains("calibration")) {
      const nlohmann::json& platt = doc.at("calibration").at("platt");
      c.platt_a = platt.at(0).get<double>(), c.platt_b = platt.at(1).get<double>();
      if (!std::isfinite(c.platt_a) || !std::isfinite(c.platt_b) || c.platt_a <= 0.0)
        return bad("calibration.platt must be two finite numbers, the first > 0");
    }
    if (doc.contains("shape")) {
      if (const Status s = read_shape_head(doc.at("shape"), c.shape); !s.ok()) return bad(s.message());
    }
  } catch (const nlohmann::json::exception& e) {
    return bad(std::string("missing or wrong field (") + e.what() + ")");
  }
  return c;
}

std::string percent(double x) {
  char b[16];
  std::snprintf(b, sizeof b, "%.0f %%", 100.0 * x);
  return b;
}

class ClassifierIdentifier final : public Identifier {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("classifier")
        .file("model", model_path_,
              "an ONNX image classifier (OpenCV's dnn reads it); \"\" = the shipped kind classifier")
        .file("labels", labels_path_,
              "its classes in output order, one a line or a JSON array: WordNet ids (n03376595), words, or both")
        .integer("size", size_, 32, 1024, "pixels", "the network's square input side")
        .choice("normalization", normalization_,
                {{"minus-one-to-one", Normalization::kMinusOneToOne},
                 {"imagenet", Normalization::kImageNet},
                 {"zero-to-one", Normalization::kZeroToOne}},
                "its input's pixel values: (x-127.5)/127.5 (TensorFlow), ImageNet mean and std (torchvision), x/255")
        .choice("channels", rgb_, {{"RGB", true}, {"BGR", false}}, "its input's channel order")
        .number("min_probability", min_probability_, Range::closed(0, 1), "",
                "the least mean probability over the views for a kind to be a candidate")
        .check([this] {
          if (user_model() != !labels_path_.empty())
            return Status::InvalidArgument(
                "classifier: model and labels go together (--identify-set model=PATH "
                "labels=PATH); without them the shipped kind classifier runs");
          loaded_ = false;  // read again, with these settings, at the next identify
          return Status::Ok();
        });
  }

  Result<Identification> identify(const IdentifyInput& in) const override {
    Identification id;
    const bool can_render = in.renderer != nullptr && in.model != nullptr;
    if (!can_render && (in.views == nullptr || in.views->empty())) {
      id.notes.push_back("classifier: no rendered views");
      return id;
    }
    std::lock_guard<std::mutex> lock(mutex_);  // the network is loaded once and is not reentrant
    if (const Status s = load(); !s.ok()) {
      id.warnings.push_back("the classifier is not available (" + s.message() + "); not identified by it");
      return id;
    }
    const ObjectTable& table = in.table != nullptr ? *in.table : ObjectTable::shipped();
    std::vector<ImageU8> inputs;  // the network's inputs, one a view that shows the object
    if (can_render) {
      ClassifierViewOptions o;
      o.size = input_size_;
      o.count = kViews;
      o.elevation_deg = kElevationDeg;
      o.background = kBackground;
      Result<std::vector<ImageU8>> rendered = classifier_views(*in.renderer, in.model->mesh, o);
      if (!rendered.ok()) return rendered.status().with_context("classifier");
      inputs = std::move(*rendered);
    } else {
      for (const View& view : *in.views) {
        if (view.rgb.empty() || view.rgb.channels() != 3)
          return Status::InvalidArgument("classifier: the views need RGB");
        ImageU8 crop = classifier_crop(view, input_size_, kBackground);
        if (!crop.empty()) inputs.push_back(std::move(crop));
      }
    }
    // The mean of the views' probabilities per class (background first, if any).
    std::vector<double> mean(labels_.size() + offset_, 0.0);
    int seen = 0;
    for (const ImageU8& input : inputs) {
      Result<std::vector<double>> p = probabilities(input);
      if (!p.ok()) return p.status();
      ++seen;
      for (std::size_t c = 0; c < mean.size(); ++c) mean[c] += (*p)[c];
    }
    if (seen == 0) {
      id.notes.push_back("classifier: no view shows the object");
      return id;
    }
    for (double& x : mean) x /= seen;
    // Joined with the shape head's probabilities, where the card has one.
    std::vector<double> joined = mean;
    bool shaped = false;
    if (!shape_.empty()) {
      const std::vector<double> cues = in.model != nullptr ? shape_cues(in.model->mesh) : std::vector<double>();
      if (cues.empty()) {
        id.notes.push_back(
            "classifier: " + std::string(in.model != nullptr ? "the mesh has no extent to measure" : "no mesh") +
            "; named from its views alone, without its shape");
      } else {
        const std::vector<double> logp = shape_.log_probabilities(cues);
        double top = -INFINITY, sum = 0.0;
        for (std::size_t c = 0; c < joined.size(); ++c)
          top = std::max(top, joined[c] = std::log(std::max(mean[c], 1e-12)) + shape_.weight * logp[c]);
        for (double& x : joined) sum += (x = std::exp(x - top));
        for (double& x : joined) x /= sum;
        shaped = true;
      }
    }
    std::vector<int> kinds(labels_.size());
    for (std::size_t c = 0; c < labels_.size(); ++c) kinds[c] = kind_of(labels_[c], table);
    std::map<int, std::pair<double, double>> kind_p;      // kind -> probability (joined, views alone)
    std::map<int, std::map<std::size_t, double>> by;      // kind -> class -> probability
    std::pair<double, std::size_t> top_unmapped{0.0, 0};  // the likeliest class that names no kind
    for (std::size_t c = 0; c < labels_.size(); ++c) {
      const double x = joined[c + offset_];
      if (kinds[c] >= 0) {
        kind_p[kinds[c]].first += x;
        kind_p[kinds[c]].second += mean[c + offset_];
        by[kinds[c]][c] += x;
      } else {
        top_unmapped = std::max(top_unmapped, {x, c});
      }
    }
    for (const auto& [kind, p] : kind_p) {
      const double confidence = calibrated(p.first);
      if (confidence < min_probability_ || confidence <= 0.0) continue;
      std::vector<std::pair<double, std::size_t>> classes;
      for (const auto& [c, x] : by[kind]) classes.emplace_back(x, c);
      std::sort(classes.begin(), classes.end(), std::greater<>());
      std::string evidence = "'" + labels_[classes.front().second].text + "'";
      if (classes.size() > 1) evidence += " and " + std::to_string(classes.size() - 1) + " more of its classes";
      evidence += ", " + percent(p.second) + " over " + std::to_string(seen) + " views";
      if (shaped) evidence += ", " + percent(p.first) + " with its shape";
      id.candidates.push_back({table.kinds()[static_cast<std::size_t>(kind)].name, confidence, "classifier", evidence});
    }
    std::stable_sort(id.candidates.begin(), id.candidates.end(),
                     [](const KindGuess& a, const KindGuess& b) { return a.confidence > b.confidence; });
    if (top_unmapped.first >= min_probability_)
      id.notes.push_back("classifier: '" + labels_[top_unmapped.second].text + "' (" + percent(top_unmapped.first) +
                         "), which no kind of the object table answers for");
    if (id.candidates.empty())
      id.notes.push_back("classifier: no class of a kind reached " + percent(min_probability_));
    return id;
  }

 private:
  Status load() const {
    if (loaded_) return load_status_;
    loaded_ = true;
    model_file_ = model_path_, labels_file_ = labels_path_;
    input_size_ = size_, input_normalization_ = normalization_, input_rgb_ = rgb_;
    platt_a_ = 1.0, platt_b_ = 0.0;
    shape_ = ShapeHead();
    if (!user_model()) {
      const std::string card = detail::shipped_model_file(kShippedCard);
      if (card.empty())
        return load_status_ = Status::NotFound(std::string(kShippedCard) +
                                               " was not found in $G2P_MODEL_DIR, libg2p/data/models or "
                                               "share/g2p/models");
      Result<ClassifierCard> c = read_card(card);
      if (!c.ok()) return load_status_ = c.status();
      model_file_ = c->model, labels_file_ = c->labels;
      input_size_ = c->size, input_normalization_ = c->normalization, input_rgb_ = c->rgb;
      platt_a_ = c->platt_a, platt_b_ = c->platt_b;
      shape_ = std::move(c->shape);
    }
    Result<std::vector<ClassLabel>> labels = read_labels(labels_file_);
    if (!labels.ok()) return load_status_ = labels.status();
    labels_ = std::move(*labels);
    try {
      net_ = cv::dnn::readNet(model_file_);
      net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
      net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    } catch (const cv::Exception& e) {
      return load_status_ = Status::IoError(model_name() + ": OpenCV could not load it (" + e.what() + ")");
    }
    if (net_.empty()) return load_status_ = Status::IoError(model_name() + ": OpenCV could not load it");
    // The number of scores, from a grey image: as many as labels, or one more
    // (a leading background class).
    Result<std::vector<float>> scores =
        forward(cv::Mat(input_size_, input_size_, CV_8UC3, cv::Scalar::all(kBackground)));
    if (!scores.ok()) return load_status_ = scores.status();
    if (scores->size() == labels_.size()) {
      offset_ = 0;
    } else if (scores->size() == labels_.size() + 1) {
      offset_ = 1;
    } else {
      return load_status_ = Status::InvalidArgument(
                 model_name() + " gives " + std::to_string(scores->size()) + " scores but " + labels_name() +
                 " names " + std::to_string(labels_.size()) +
                 " classes (as many are needed, or one fewer when the first score is a background class)");
    }
    if (!shape_.empty() && static_cast<std::size_t>(shape_.classes()) != scores->size())
      return load_status_ = Status::InvalidArgument(std::string(kShippedCard) + ": the shape head gives " +
                                                    std::to_string(shape_.classes()) + " classes, the network " +
                                                    std::to_string(scores->size()));
    return load_status_ = Status::Ok();
  }

  // The network's scores for an RGB image of input_size_ x input_size_.
  Result<std::vector<float>> forward(const cv::Mat& rgb) const {
    cv::Mat input;
    if (!input_rgb_)
      cv::cvtColor(rgb, input, cv::COLOR_RGB2BGR);
    else
      input = rgb;
    cv::Mat blob;
    switch (input_normalization_) {
      case Normalization::kMinusOneToOne:
        blob = cv::dnn::blobFromImage(input, 1.0 / 127.5, cv::Size(), cv::Scalar::all(127.5), false, false);
        break;
      case Normalization::kZeroToOne:
        blob = cv::dnn::blobFromImage(input, 1.0 / 255.0, cv::Size(), cv::Scalar(), false, false);
        break;
      case Normalization::kImageNet: {
        // (x / 255 - mean) / std per channel, in the input's channel order.
        cv::Mat f;
        input.convertTo(f, CV_32FC3, 1.0 / 255.0);
        const double mean[3] = {0.485, 0.456, 0.406}, std[3] = {0.229, 0.224, 0.225};  // RGB
        std::vector<cv::Mat> planes;
        cv::split(f, planes);
        for (int c = 0; c < 3; ++c) {
          const int k = input_rgb_ ? c : 2 - c;
          planes[static_cast<std::size_t>(c)] = (planes[static_cast<std::size_t>(c)] - mean[k]) / std[k];
        }
        cv::merge(planes, f);
        blob = cv::dnn::blobFromImage(f);
        break;
      }
    }
    cv::Mat out;
    try {
      net_.setInput(blob);
      out = net_.forward();
    } catch (const cv::Exception& e) {
      return Status::Internal(std::string("classifier: inference failed (is size=") + std::to_string(input_size_) +
                              " its input side?): " + e.what());
    }
    const cv::Mat flat = out.reshape(1, 1);
    std::vector<float> scores(flat.ptr<float>(), flat.ptr<float>() + flat.total());
    return scores;
  }

  // The network's class probabilities for one input (classifier_crop()),
  // with the background score, if any, first.
  Result<std::vector<double>> probabilities(const ImageU8& input) const {
    const cv::Mat scaled(input.height(), input.width(), CV_8UC3, const_cast<std::uint8_t*>(input.data()));
    Result<std::vector<float>> scores = forward(scaled);
    if (!scores.ok()) return scores.status();
    if (scores->size() != labels_.size() + offset_)
      return Status::Internal("classifier: the network's output changed size between views");
    std::vector<double> p(scores->begin(), scores->end());
    double sum = 0.0;
    bool probabilities = true;
    for (double x : p) {
      probabilities = probabilities && x >= 0.0 && x <= 1.0;
      sum += x;
    }
    if (!probabilities || std::abs(sum - 1.0) > 0.01) {  // logits: a softmax
      const double top = *std::max_element(p.begin(), p.end());
      sum = 0.0;
      for (double& x : p) sum += (x = std::exp(x - top));
    }
    for (double& x : p) x /= sum;
    return p;
  }

  static constexpr int kViews = 8;
  static constexpr double kElevationDeg = 15.0;
  static constexpr int kBackground = 128;

  bool user_model() const { return !model_path_.empty(); }
  std::string model_name() const { return user_model() ? "model=" + model_file_ : model_file_; }
  std::string labels_name() const { return user_model() ? "labels=" + labels_file_ : labels_file_; }

  std::string model_path_, labels_path_;
  int size_ = 224;
  Normalization normalization_ = Normalization::kMinusOneToOne;
  bool rgb_ = true;
  double min_probability_ = 0.05;
  // What load() read: the user's files and settings, or the shipped card's.
  mutable std::string model_file_, labels_file_;
  mutable int input_size_ = 224;
  mutable Normalization input_normalization_ = Normalization::kMinusOneToOne;
  mutable bool input_rgb_ = true;
  mutable double platt_a_ = 1.0, platt_b_ = 0.0;
  mutable ShapeHead shape_;

  // A kind's mean probability over the views as the confidence the card's
  // calibration makes of it (how often a top kind that sure was right).
  double calibrated(double p) const {
    if (platt_a_ == 1.0 && platt_b_ == 0.0) return p;
    const double q = std::clamp(p, 1e-6, 1.0 - 1e-6);
    return 1.0 / (1.0 + std::exp(-(platt_a_ * std::log(q / (1.0 - q)) + platt_b_)));
  }
  mutable bool loaded_ = false;
  mutable Status load_status_;
  mutable std::vector<ClassLabel> labels_;
  mutable std::size_t offset_ = 0;  // 1: the first score is a background class
  mutable cv::dnn::Net net_;
  mutable std::mutex mutex_;
};

}  // namespace

std::unique_ptr<Identifier> detail::make_classifier_identifier() { return std::make_unique<ClassifierIdentifier>(); }

}  // namespace g2p
