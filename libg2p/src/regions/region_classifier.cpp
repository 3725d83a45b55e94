// The region classifier: OpenCV random trees (Breiman 2001, cv::ml::RTrees)
// behind a model card. Probabilities are the share of trees voting for each
// class. RTrees seeds its own generator when it is created, so the same rows
// give the same trees.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include "g2p/regions.h"
#include "segment/backends.h"

namespace g2p {

struct RegionClassifier::Impl {
  cv::Ptr<cv::ml::RTrees> trees;
  int classes = 0;
  int features = 0;
  std::string card;
};

RegionClassifier::RegionClassifier() : impl_(std::make_unique<Impl>()) {}
RegionClassifier::~RegionClassifier() = default;
RegionClassifier::RegionClassifier(RegionClassifier&&) noexcept = default;
RegionClassifier& RegionClassifier::operator=(RegionClassifier&&) noexcept = default;

int RegionClassifier::num_classes() const { return impl_->classes; }
int RegionClassifier::num_features() const { return impl_->features; }
const std::string& RegionClassifier::card_path() const { return impl_->card; }

Result<RegionClassifier> RegionClassifier::load(const std::string& card_path, const MaterialTable& table) {
  std::ifstream in(card_path);
  if (!in) return Status::NotFound("region classifier card " + card_path + " cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  const nlohmann::json card = nlohmann::json::parse(text.str(), nullptr, false);
  if (card.is_discarded() || !card.is_object() || card.value("format", nlohmann::json()) != "g2p-region-classifier")
    return Status::ParseError(card_path + ": not a region classifier card (format \"g2p-region-classifier\")");
  const auto version = card.find("version");
  if (version == card.end() || !version->is_number_integer() || version->get<long long>() != 1)
    return Status::ParseError(card_path + ": \"version\" must be 1 (the version libg2p reads)");
  std::vector<std::string> classes, features;
  try {
    classes = card.at("classes").get<std::vector<std::string>>();
    features = card.at("features").get<std::vector<std::string>>();
  } catch (const nlohmann::json::exception&) {
    return Status::ParseError(card_path + ": \"classes\" and \"features\" must be lists of names");
  }
  std::vector<std::string> table_classes;
  for (const MaterialClass& c : table.classes()) table_classes.push_back(c.name);
  if (classes != table_classes)
    return Status::InvalidArgument(card_path + ": trained for other classes than the material table's");
  if (features != region_feature_names(table))
    return Status::InvalidArgument(card_path + ": trained on other features than this libg2p computes");
  const nlohmann::json trees_name = card.value("trees", nlohmann::json());
  if (!trees_name.is_string() || trees_name.get<std::string>().empty())
    return Status::ParseError(card_path + ": \"trees\" must name the trees file");
  const std::filesystem::path trees_path =
      std::filesystem::path(card_path).parent_path() / trees_name.get<std::string>();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(trees_path, ec))
    return Status::NotFound("region classifier trees " + trees_path.string() + " (named by " + card_path +
                            ") do not exist");
  RegionClassifier out;
  try {
    out.impl_->trees = cv::ml::RTrees::load(trees_path.string());
  } catch (const cv::Exception& e) {
    return Status::ParseError("region classifier trees " + trees_path.string() + ": " + e.what());
  }
  if (out.impl_->trees.empty() || !out.impl_->trees->isTrained() ||
      out.impl_->trees->getVarCount() != static_cast<int>(features.size()))
    return Status::ParseError("region classifier trees " + trees_path.string() + ": not trained on " +
                              std::to_string(features.size()) + " features");
  // The trees' classes must be the table's indices (trees for another table
  // with as many features would otherwise pass).
  try {
    cv::Mat votes;
    const cv::Mat probe = cv::Mat::zeros(1, static_cast<int>(features.size()), CV_32F);
    out.impl_->trees->getVotes(probe, votes, 0);
    for (int c = 0; c < votes.cols; ++c)
      if (votes.type() != CV_32S || votes.at<int>(0, c) < 0 || votes.at<int>(0, c) >= table.size())
        return Status::ParseError("region classifier trees " + trees_path.string() + ": class " +
                                  std::to_string(votes.at<int>(0, c)) + " is not one of the card's " +
                                  std::to_string(table.size()));
  } catch (const cv::Exception& e) {
    return Status::ParseError("region classifier trees " + trees_path.string() + ": " + e.what());
  }
  out.impl_->classes = table.size();
  out.impl_->features = static_cast<int>(features.size());
  out.impl_->card = card_path;
  return out;
}

Result<std::vector<float>> RegionClassifier::predict(const std::vector<float>& features, int rows) const {
  if (impl_->trees.empty()) return Status::Unavailable("region classifier: not loaded");
  const std::string who = "region classifier " + impl_->card + ": ";
  if (rows < 0 || features.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(impl_->features))
    return Status::InvalidArgument(who + std::to_string(features.size()) + " values for " + std::to_string(rows) +
                                   " rows of " + std::to_string(impl_->features) + " features");
  std::vector<float> out(static_cast<std::size_t>(rows) * static_cast<std::size_t>(impl_->classes), 0.f);
  if (rows == 0) return out;
  const cv::Mat samples(rows, impl_->features, CV_32F, const_cast<float*>(features.data()));
  cv::Mat votes;
  try {
    impl_->trees->getVotes(samples, votes, 0);
  } catch (const cv::Exception& e) {
    return Status::Internal(who + e.what());
  }
  // Row 0 holds the class of each column, rows 1..rows the trees' votes.
  if (votes.rows != rows + 1 || votes.type() != CV_32S) return Status::Internal(who + "unexpected vote matrix");
  for (int r = 0; r < rows; ++r) {
    double sum = 0.0;
    for (int c = 0; c < votes.cols; ++c) sum += votes.at<int>(r + 1, c);
    if (sum <= 0.0) continue;
    for (int c = 0; c < votes.cols; ++c) {
      const int cls = votes.at<int>(0, c);
      if (cls >= 0 && cls < impl_->classes)
        out[static_cast<std::size_t>(r) * impl_->classes + cls] = static_cast<float>(votes.at<int>(r + 1, c) / sum);
    }
  }
  return out;
}

Status train_region_classifier(const std::vector<float>& features, const std::vector<int>& labels,
                               const std::vector<float>& weights, int num_features, int num_classes,
                               const RegionTrainOptions& options, const std::string& trees_path) {
  const std::size_t rows = labels.size();
  if (num_features <= 0 || features.size() != rows * static_cast<std::size_t>(num_features) || weights.size() != rows ||
      rows == 0)
    return Status::InvalidArgument("train_region_classifier: features, labels and weights disagree or are empty");
  for (const float w : weights)
    if (!(w >= 0.f) || !std::isfinite(w))
      return Status::InvalidArgument("train_region_classifier: a weight is negative or not finite");
  for (const int l : labels)
    if (l < 0 || l >= num_classes) return Status::InvalidArgument("train_region_classifier: label out of range");
  if (options.trees < 1 || options.max_depth < 1 || options.min_samples < 1 || options.features_per_split < 0)
    return Status::InvalidArgument("train_region_classifier: trees, depth and node size must be positive");
  const cv::Mat samples(static_cast<int>(rows), num_features, CV_32F, const_cast<float*>(features.data()));
  cv::Mat responses(static_cast<int>(rows), 1, CV_32S);
  for (std::size_t i = 0; i < rows; ++i) responses.at<int>(static_cast<int>(i)) = labels[i];
  const cv::Mat sample_weights(static_cast<int>(rows), 1, CV_32F, const_cast<float*>(weights.data()));
  cv::Mat var_type(num_features + 1, 1, CV_8U, cv::Scalar(cv::ml::VAR_ORDERED));
  var_type.at<unsigned char>(num_features) = cv::ml::VAR_CATEGORICAL;
  try {
    cv::Ptr<cv::ml::TrainData> data = cv::ml::TrainData::create(samples, cv::ml::ROW_SAMPLE, responses, cv::noArray(),
                                                                cv::noArray(), sample_weights, var_type);
    cv::Ptr<cv::ml::RTrees> trees = cv::ml::RTrees::create();
    trees->setMaxDepth(options.max_depth);
    trees->setMinSampleCount(options.min_samples);
    trees->setActiveVarCount(options.features_per_split);
    trees->setCalculateVarImportance(false);
    trees->setUseSurrogates(false);
    trees->setMaxCategories(std::max(num_classes, 2));
    trees->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, options.trees, 0.0));
    if (!trees->train(data)) return Status::Internal("train_region_classifier: OpenCV did not train");
    trees->save(trees_path);
  } catch (const cv::Exception& e) {
    return Status::Internal(std::string("train_region_classifier: ") + e.what());
  }
  return Status::Ok();
}

std::string shipped_region_card() { return detail::shipped_model_file("g2p-regions.json"); }

}  // namespace g2p
