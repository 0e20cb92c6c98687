#include "grpc_reflection.h"

#include <algorithm>
#include <utility>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <grpcpp/support/status.h>

namespace haarcast::net {
namespace {

namespace pb = google::protobuf;
using grpc::reflection::v1::ServerReflectionRequest;
using grpc::reflection::v1::ServerReflectionResponse;

// The file, then what it imports (depth first), each once per stream.
void addFile(const pb::FileDescriptor* file, std::vector<std::string>& sent, grpc::reflection::v1::FileDescriptorResponse& out) {
  if (std::find(sent.begin(), sent.end(), file->name()) != sent.end()) return;
  sent.push_back(file->name());
  pb::FileDescriptorProto proto;
  file->CopyTo(&proto);
  out.add_file_descriptor_proto(proto.SerializeAsString());
  for (int i = 0; i < file->dependency_count(); ++i) addFile(file->dependency(i), sent, out);
}

void notFound(ServerReflectionResponse& out, const std::string& what) {
  out.mutable_error_response()->set_error_code(static_cast<int>(grpc::StatusCode::NOT_FOUND));
  out.mutable_error_response()->set_error_message(what);
}

// One stream: read a request, write its answer, until the client is done.
class Reactor final : public grpc::ServerBidiReactor<ServerReflectionRequest, ServerReflectionResponse> {
 public:
  explicit Reactor(const ReflectionV1Service& service) : service_(service) { StartRead(&request_); }

  void OnReadDone(bool ok) override {
    if (!ok) {
      Finish(grpc::Status::OK);
      return;
    }
    response_ = service_.answer(request_, sent_);
    StartWrite(&response_);
  }

  void OnWriteDone(bool ok) override {
    if (!ok) {
      Finish(grpc::Status(grpc::StatusCode::UNKNOWN, "the reflection answer could not be written"));
      return;
    }
    StartRead(&request_);
  }

  void OnDone() override { delete this; }

 private:
  const ReflectionV1Service& service_;
  ServerReflectionRequest request_;
  ServerReflectionResponse response_;
  std::vector<std::string> sent_;
};

}  // namespace

ReflectionV1Service::ReflectionV1Service(std::vector<std::string> services) : services_(std::move(services)) {}

grpc::ServerBidiReactor<ServerReflectionRequest, ServerReflectionResponse>* ReflectionV1Service::ServerReflectionInfo(
    grpc::CallbackServerContext* /*context*/) {
  return new Reactor(*this);
}

ServerReflectionResponse ReflectionV1Service::answer(const ServerReflectionRequest& request, std::vector<std::string>& sent) const {
  const pb::DescriptorPool* pool = pb::DescriptorPool::generated_pool();
  ServerReflectionResponse out;
  out.set_valid_host(request.host());
  *out.mutable_original_request() = request;
  // The file with its imports, or NOT_FOUND saying what was looked for.
  auto answerFile = [&](const pb::FileDescriptor* file, const std::string& missing) {
    if (file) {
      addFile(file, sent, *out.mutable_file_descriptor_response());
    } else {
      notFound(out, missing);
    }
  };
  switch (request.message_request_case()) {
    case ServerReflectionRequest::kListServices:
      for (const std::string& name : services_) out.mutable_list_services_response()->add_service()->set_name(name);
      break;
    case ServerReflectionRequest::kFileByFilename:
      answerFile(pool->FindFileByName(request.file_by_filename()), "no file named " + request.file_by_filename());
      break;
    case ServerReflectionRequest::kFileContainingSymbol:
      answerFile(pool->FindFileContainingSymbol(request.file_containing_symbol()),
                 "no symbol named " + request.file_containing_symbol());
      break;
    case ServerReflectionRequest::kFileContainingExtension: {
      const auto& e = request.file_containing_extension();
      const pb::Descriptor* type = pool->FindMessageTypeByName(e.containing_type());
      const pb::FieldDescriptor* field = type ? pool->FindExtensionByNumber(type, e.extension_number()) : nullptr;
      answerFile(field ? field->file() : nullptr,
                 "no extension " + std::to_string(e.extension_number()) + " of " + e.containing_type());
      break;
    }
    case ServerReflectionRequest::kAllExtensionNumbersOfType:
      if (const pb::Descriptor* type = pool->FindMessageTypeByName(request.all_extension_numbers_of_type())) {
        std::vector<const pb::FieldDescriptor*> extensions;
        pool->FindAllExtensions(type, &extensions);
        auto* numbers = out.mutable_all_extension_numbers_response();
        numbers->set_base_type_name(type->full_name());
        for (const pb::FieldDescriptor* x : extensions) numbers->add_extension_number(x->number());
      } else {
        notFound(out, "no message type named " + request.all_extension_numbers_of_type());
      }
      break;
    case ServerReflectionRequest::MESSAGE_REQUEST_NOT_SET:
      out.mutable_error_response()->set_error_code(static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
      out.mutable_error_response()->set_error_message(
          "the request names nothing: set one of file_by_filename, file_containing_symbol, file_containing_extension, "
          "all_extension_numbers_of_type, list_services");
      break;
  }
  return out;
}

}  // namespace haarcast::net
