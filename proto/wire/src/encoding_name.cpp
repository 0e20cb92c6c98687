#include "haarcast/wire/encoding_name.h"

#include <cctype>
#include <string>
#include <utility>
#include <vector>

namespace haarcast::wire {
namespace {

// Names the enum's value names do not give: the ones printed before the
// names came from the descriptor, kept so that flags, logs and reports read
// as they did. Keyed by the enum; tests/unit/wire checks the names they give.
constexpr std::pair<v1::Encoding, std::string_view> kNameExceptions[] = {
    {v1::ENCODING_RAW_RGBA8, "raw"},
};

constexpr std::string_view kValuePrefix = "ENCODING_";

struct Names {
  std::vector<std::pair<int, std::string>> byNumber;  // every value of the enum, in declaration order

  Names() {
    const google::protobuf::EnumDescriptor* descriptor = v1::Encoding_descriptor();
    for (int i = 0; i < descriptor->value_count(); ++i) {
      const google::protobuf::EnumValueDescriptor* value = descriptor->value(i);
      std::string name;
      for (const auto& [encoding, exception] : kNameExceptions) {
        if (encoding == value->number()) name = exception;
      }
      if (name.empty()) {
        std::string_view full = value->name();
        if (full.substr(0, kValuePrefix.size()) == kValuePrefix) full.remove_prefix(kValuePrefix.size());
        for (const char c : full) name += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      }
      byNumber.emplace_back(value->number(), std::move(name));
    }
  }
};

const Names& names() {
  static const Names table;
  return table;
}

}  // namespace

std::string_view encodingName(v1::Encoding encoding) {
  for (const auto& [number, name] : names().byNumber) {
    if (number == encoding) return name;
  }
  return "unknown";
}

std::optional<v1::Encoding> encodingFromName(std::string_view name) {
  for (const auto& [number, known] : names().byNumber) {
    if (known == name) return static_cast<v1::Encoding>(number);
  }
  return std::nullopt;
}

}  // namespace haarcast::wire
