// Who is calling: bearer tokens from a file (token -> client name) checked on
// every MeshingService call, and the TLS / mTLS server credentials.
// docs/security.md has the file formats and the threat model.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server_context.h"

namespace svrc::server {

class TokenAuth {
 public:
  // One "TOKEN CLIENT_NAME" per line; blank lines and '#' comments ignored.
  // Tokens are kept only as SHA-256 digests; they are never logged.
  static absl::StatusOr<std::unique_ptr<TokenAuth>> Load(const std::string& path);

  // The client name for the call's "authorization: Bearer TOKEN" metadata;
  // UNAUTHENTICATED when it is missing or unknown (same message for both
  // wrong and unknown tokens).
  absl::StatusOr<std::string> Authenticate(const grpc::ServerContextBase& context) const;
  size_t size() const { return clients_.size(); }

 private:
  std::map<std::string, std::string> clients_;  // sha256 hex of token -> name
};

// Server credentials: TLS when `cert`/`key` are set (PEM files), requiring and
// verifying client certificates when `client_ca` is set too (mTLS);
// insecure when all three are empty.
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const std::string& cert, const std::string& key, const std::string& client_ca);

// The whole file as a string (NOT_FOUND / INTERNAL).
absl::StatusOr<std::string> ReadSmallFile(const std::string& path);

}  // namespace svrc::server
