#include "ros2/split_bag_log.hpp"

#include <algorithm>
#include <map>
#include <utility>

namespace featsense::slam {
namespace {

/// The cursors of one topic in each file, one after the other.
class ChainedCursor final : public MessageCursor {
 public:
  ChainedCursor(const std::vector<std::unique_ptr<MessageLog>>& files, const BagTopic& topic,
                WarningSink warn)
      : files_(files), topic_(topic), warn_(std::move(warn)) {}

  std::optional<BagMessage> next() override {
    for (;;) {
      if (!current_) {
        if (file_ == files_.size()) return std::nullopt;
        const MessageLog& file = *files_[file_];
        const BagTopic* here = file.catalog().find(topic_.name);
        ++file_;
        if (here == nullptr) continue;  // the topic started in a later file
        current_ = files_[file_ - 1]->open(*here, warn_);
      }
      if (std::optional<BagMessage> message = current_->next()) return message;
      current_.reset();
    }
  }

 private:
  const std::vector<std::unique_ptr<MessageLog>>& files_;
  BagTopic topic_;
  WarningSink warn_;
  size_t file_ = 0;
  std::unique_ptr<MessageCursor> current_;
};

class SplitBagLog final : public MessageLog {
 public:
  explicit SplitBagLog(std::vector<std::unique_ptr<MessageLog>> files) : files_(std::move(files)) {
    std::map<std::string, BagTopic> topics;
    for (const std::unique_ptr<MessageLog>& file : files_) {
      const BagCatalog& part = file->catalog();
      for (const BagTopic& topic : part.topics) {
        auto [it, added] = topics.emplace(topic.name, topic);
        if (!added) it->second.messages += topic.messages;
      }
      for (const std::string& name : part.compressions) {
        if (std::find(catalog_.compressions.begin(), catalog_.compressions.end(), name) ==
            catalog_.compressions.end()) {
          catalog_.compressions.push_back(name);
        }
      }
      catalog_.chunks += part.chunks;
      catalog_.warnings.insert(catalog_.warnings.end(), part.warnings.begin(), part.warnings.end());
    }
    for (auto& [name, topic] : topics) catalog_.topics.push_back(std::move(topic));
  }

  const BagCatalog& catalog() const override { return catalog_; }

  std::unique_ptr<MessageCursor> open(const BagTopic& topic, WarningSink warn) override {
    return std::make_unique<ChainedCursor>(files_, topic, std::move(warn));
  }

  std::string describe() const override {
    return std::to_string(files_.size()) + " files, " + files_.front()->describe();
  }

 private:
  std::vector<std::unique_ptr<MessageLog>> files_;
  BagCatalog catalog_;
};

}  // namespace

std::unique_ptr<MessageLog> join_bag_files(std::vector<std::unique_ptr<MessageLog>> files) {
  if (files.size() == 1) return std::move(files.front());
  return std::make_unique<SplitBagLog>(std::move(files));
}

}  // namespace featsense::slam
