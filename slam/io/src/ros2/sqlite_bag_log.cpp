#include "ros2/sqlite_bag_log.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <map>
#include <optional>
#include <utility>

#include "rosbag/bag_topic_choice.hpp"

namespace featsense::slam {
namespace {

/// How a rosbag2 topic's messages are serialized, from the topics table's
/// serialization_format: "cdr", and the empty string that older rosbag2 versions wrote, mean
/// CDR (what every ROS 2 middleware serializes to; each message's encapsulation header then
/// gives its byte order); "ros1" is a bag converted from ROS 1. Anything else is not read.
std::optional<MessageEncoding> rosbag2_encoding(const std::string& format) {
  if (format.empty() || format == "cdr") return MessageEncoding::kCdr;
  if (format == "ros1") return MessageEncoding::kRos1;
  return std::nullopt;
}

/// Owns a connection; closed when the log goes.
struct DatabaseCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Database = std::unique_ptr<sqlite3, DatabaseCloser>;

struct StatementFinalizer {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

std::string column_text(sqlite3_stmt* statement, int column) {
  const unsigned char* text = sqlite3_column_text(statement, column);
  return text == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(text));
}

/// The messages of one topic id, oldest first (rosbag2 writes in arrival order; the
/// timestamp index makes this order cheap).
class SqliteCursor final : public MessageCursor {
 public:
  SqliteCursor(sqlite3* db, const std::string& path, int64_t topic_id, WarningSink warn)
      : path_(path), warn_(std::move(warn)) {
    sqlite3_stmt* raw = nullptr;
    const int rc = sqlite3_prepare_v2(
        db, "SELECT timestamp, data, id FROM messages WHERE topic_id = ? ORDER BY timestamp, id",
        -1, &raw, nullptr);
    statement_.reset(raw);
    if (rc != SQLITE_OK) {
      fail(std::string("cannot query the messages: ") + sqlite3_errmsg(db));
      return;
    }
    sqlite3_bind_int64(statement_.get(), 1, topic_id);
  }

  std::optional<BagMessage> next() override {
    if (done_) return std::nullopt;
    const int rc = sqlite3_step(statement_.get());
    if (rc == SQLITE_DONE) {
      done_ = true;
      return std::nullopt;
    }
    if (rc != SQLITE_ROW) {
      fail("reading stopped after " + std::to_string(count_) + " messages: " + sqlite3_errstr(rc) +
           " (a damaged or cut-off file?)");
      return std::nullopt;
    }
    ++count_;
    BagMessage message;
    message.time_ns = sqlite3_column_int64(statement_.get(), 0);
    const void* blob = sqlite3_column_blob(statement_.get(), 1);
    const int size = sqlite3_column_bytes(statement_.get(), 1);
    message.data = {static_cast<const uint8_t*>(blob), size > 0 ? static_cast<size_t>(size) : 0};
    message.offset = static_cast<uint64_t>(sqlite3_column_int64(statement_.get(), 2));
    return message;
  }

 private:
  void fail(const std::string& problem) {
    done_ = true;
    if (warn_) warn_(path_ + ": " + problem);
  }

  std::string path_;
  WarningSink warn_;
  Statement statement_;
  uint64_t count_ = 0;
  bool done_ = false;
};

class SqliteBagLog final : public MessageLog {
 public:
  explicit SqliteBagLog(std::string path) : path_(std::move(path)) {
    sqlite3* raw = nullptr;
    const int rc = sqlite3_open_v2(path_.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
    db_.reset(raw);
    if (rc != SQLITE_OK) fail("cannot open it as an SQLite database", rc);
    read_topics();
  }

  const BagCatalog& catalog() const override { return catalog_; }

  std::unique_ptr<MessageCursor> open(const BagTopic& topic, WarningSink warn) override {
    const auto id = topic_ids_.find(topic.name);
    return std::make_unique<SqliteCursor>(
        db_.get(), path_, id == topic_ids_.end() ? -1 : id->second, std::move(warn));
  }

  std::string describe() const override { return "sqlite3"; }

 private:
  [[noreturn]] void fail(const std::string& what, int rc) {
    throw InputError(path_ + ": " + what + " (" + sqlite3_errstr(rc) +
                     "); is it a ROS 2 bag file (.db3), whole?");
  }

  Statement prepare(const char* sql) {
    sqlite3_stmt* raw = nullptr;
    const int rc = sqlite3_prepare_v2(db_.get(), sql, -1, &raw, nullptr);
    Statement statement(raw);
    if (rc != SQLITE_OK) {
      throw InputError(path_ + ": not a ROS 2 bag (" + sqlite3_errmsg(db_.get()) + ")");
    }
    return statement;
  }

  void read_topics() {
    std::map<int64_t, BagTopic> by_id;
    Statement topics = prepare("SELECT id, name, type, serialization_format FROM topics");
    int rc = SQLITE_OK;
    while ((rc = sqlite3_step(topics.get())) == SQLITE_ROW) {
      BagTopic topic;
      topic.name = column_text(topics.get(), 1);
      topic.type = ros1_style_type(column_text(topics.get(), 2));
      const std::string format = column_text(topics.get(), 3);
      if (const std::optional<MessageEncoding> encoding = rosbag2_encoding(format)) {
        topic.encoding = *encoding;
      } else {
        // Shown with its serialization, never decoded as a scan.
        topic.type += " (" + format + " serialization)";
        catalog_.warnings.push_back(path_ + ": topic " + topic.name + " is serialized as '" +
                                    format + "', which is neither CDR nor ROS 1: not read");
      }
      by_id[sqlite3_column_int64(topics.get(), 0)] = std::move(topic);
    }
    if (rc != SQLITE_DONE) fail("cannot read the topics table", rc);
    Statement counts = prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id");
    while ((rc = sqlite3_step(counts.get())) == SQLITE_ROW) {
      const auto topic = by_id.find(sqlite3_column_int64(counts.get(), 0));
      if (topic != by_id.end()) {
        topic->second.messages = static_cast<uint64_t>(sqlite3_column_int64(counts.get(), 1));
      }
    }
    if (rc != SQLITE_DONE) fail("cannot count the messages", rc);
    for (auto& [id, topic] : by_id) {
      topic_ids_[topic.name] = id;
      catalog_.topics.push_back(std::move(topic));
    }
    std::sort(catalog_.topics.begin(), catalog_.topics.end(),
              [](const BagTopic& a, const BagTopic& b) { return a.name < b.name; });
  }

  std::string path_;
  Database db_;
  BagCatalog catalog_;
  std::map<std::string, int64_t> topic_ids_;
};

}  // namespace

std::unique_ptr<MessageLog> open_sqlite_bag_file(const std::string& path) {
  return std::make_unique<SqliteBagLog>(path);
}

}  // namespace featsense::slam
