// The encodings' names against the proto descriptor: every value of the
// enum has one, they differ, they read back, and they are the names the
// server's flags, the CLI client and the reports have always printed.
#include "haarcast/wire/encoding_name.h"

#include <cctype>
#include <set>
#include <string>

#include <gtest/gtest.h>

namespace haarcast::wire {
namespace {

TEST(EncodingName, EveryValueOfTheProtoEnumHasADistinctNameThatReadsBack) {
  const google::protobuf::EnumDescriptor* descriptor = v1::Encoding_descriptor();
  ASSERT_GT(descriptor->value_count(), 0);
  std::set<std::string> seen;
  for (int i = 0; i < descriptor->value_count(); ++i) {
    const auto encoding = static_cast<v1::Encoding>(descriptor->value(i)->number());
    const std::string name(encodingName(encoding));
    const std::string& wire = descriptor->value(i)->name();
    EXPECT_FALSE(name.empty()) << wire;
    EXPECT_NE(name, "unknown") << wire << " has no name";
    for (const char c : name) EXPECT_FALSE(std::isupper(static_cast<unsigned char>(c))) << wire << ": " << name;
    EXPECT_EQ(name.find("encoding"), std::string::npos) << wire << ": " << name;
    EXPECT_TRUE(seen.insert(name).second) << wire << ": \"" << name << "\" names two encodings";
    EXPECT_EQ(encodingFromName(name), encoding) << name;
  }
}

TEST(EncodingName, TheNamesPrintedSoFar) {
  EXPECT_EQ(encodingName(v1::ENCODING_UNSPECIFIED), "unspecified");
  EXPECT_EQ(encodingName(v1::ENCODING_JPEG), "jpeg");
  EXPECT_EQ(encodingName(v1::ENCODING_PNG), "png");
  EXPECT_EQ(encodingName(v1::ENCODING_RAW_RGBA8), "raw");  // not the enum's "raw_rgba8"
  EXPECT_EQ(encodingName(v1::ENCODING_EXR), "exr");
  EXPECT_EQ(encodingName(v1::ENCODING_H264), "h264");
}

TEST(EncodingName, UnknownNumbersAndNames) {
  EXPECT_EQ(encodingName(static_cast<v1::Encoding>(99)), "unknown");
  EXPECT_EQ(encodingFromName("unknown"), std::nullopt);
  EXPECT_EQ(encodingFromName("webp"), std::nullopt);
  EXPECT_EQ(encodingFromName("JPEG"), std::nullopt);  // exactly the names, no aliases
  EXPECT_EQ(encodingFromName("raw_rgba8"), std::nullopt);
  EXPECT_EQ(encodingFromName(""), std::nullopt);
}

}  // namespace
}  // namespace haarcast::wire
