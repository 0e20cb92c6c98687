// Server reflection, version 1 (grpc.reflection.v1.ServerReflection), beside
// the v1alpha service that Debian's libgrpc++ 1.51 provides: current tools
// ask v1 first. Answers come from the process's generated descriptor pool,
// as v1alpha's do; the services listed are the ones the caller names.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <grpcpp/support/server_callback.h>

#include "haarcast/proto/grpc/reflection/v1/reflection.grpc.pb.h"

namespace haarcast::net {

class ReflectionV1Service final : public grpc::reflection::v1::ServerReflection::CallbackService {
 public:
  explicit ReflectionV1Service(std::vector<std::string> services);

  grpc::ServerBidiReactor<grpc::reflection::v1::ServerReflectionRequest, grpc::reflection::v1::ServerReflectionResponse>*
  ServerReflectionInfo(grpc::CallbackServerContext* context) override;

  // One request's answer (no stream): what ServerReflectionInfo writes back.
  // `sent` holds the files this stream has already carried (each is sent
  // once per stream, as the protocol allows).
  grpc::reflection::v1::ServerReflectionResponse answer(const grpc::reflection::v1::ServerReflectionRequest& request,
                                                        std::vector<std::string>& sent) const;

 private:
  std::vector<std::string> services_;
};

}  // namespace haarcast::net
