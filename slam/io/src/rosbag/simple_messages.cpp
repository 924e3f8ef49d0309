#include "rosbag/simple_messages.hpp"

#include "ros2/cdr_deserializer.hpp"

namespace featsense::slam {

ByteView byte_array_message(ByteView message, MessageEncoding encoding) {
  if (encoding == MessageEncoding::kCdr) return CdrDeserializer(message).byte_sequence("buf");
  return RosDeserializer(message).byte_array("buf");
}

std::string string_message(ByteView message, MessageEncoding encoding) {
  if (encoding == MessageEncoding::kCdr) return CdrDeserializer(message).string("String data");
  return RosDeserializer(message).string("std_msgs/String data");
}

std::optional<std::string> first_string_message(const TopicOpener& open_topic,
                                                const BagTopic& topic) {
  std::unique_ptr<MessageCursor> messages = open_topic(topic);
  while (const std::optional<BagMessage> message = messages->next()) {
    try {
      return string_message(message->data, topic.encoding);
    } catch (const SerializationError&) {
      continue;  // a damaged copy; a later message may be whole
    }
  }
  return std::nullopt;
}

}  // namespace featsense::slam
