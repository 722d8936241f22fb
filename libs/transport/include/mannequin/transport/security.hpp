#pragma once
/// \file security.hpp
/// \brief ZeroMQ CURVE (RFC 26) for the cluster's pub/sub: Z85 keys, key files, and the ZAP handler
/// (RFC 27) that lets a CURVE publisher accept only the client public keys it is given.
///
/// - Keys are Z85 text, 40 characters (32 bytes). A key file holds the key on its first line that is
///   neither empty nor a '#' comment: NAME.key (public) and NAME.key_secret (secret, mode 0600; a
///   secret file readable by group or others is refused).
/// - A publisher with PublisherOptions::curve is a CURVE server: traffic is encrypted and a client is
///   admitted only if its public key is in `authorized_keys`. The check is done by one ZAP handler per
///   ZeroMQ context (a thread answering inproc://zeromq.zap.01); each publisher gets its own ZAP domain,
///   so publishers of one context can list different keys. A refused key is logged (Z85 and peer
///   address, rate-limited per key and address) and counted (Publisher::curveRefusals()).
/// - A subscriber with SubscriberOptions::curve is a CURVE client: its key pair and the server's
///   public key, one for all its publishers or one per endpoint (CurveClientOptions::server_keys:
///   each publisher of a deployment has its own key pair). A server with another key never completes
///   the handshake: nothing is received.
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace mannequin::transport {

/// A publisher's CURVE settings (all Z85).
struct CurveServerOptions {
  std::string secret_key;                    ///< the server's secret key
  std::vector<std::string> authorized_keys;  ///< client public keys admitted (empty: nobody)
};

/// A subscriber's CURVE settings (all Z85).
struct CurveClientOptions {
  std::string public_key;         ///< the client's public key (listed by the publishers)
  std::string secret_key;         ///< the client's secret key
  std::string server_public_key;  ///< the publishers' public key ("": every endpoint must be in server_keys)
  /// Per publisher: its connect endpoint (as given to the subscriber) → its public key; an endpoint not
  /// listed uses server_public_key.
  std::map<std::string, std::string> server_keys = {};
};

struct CurveKeyPair {
  std::string public_key;  ///< Z85
  std::string secret_key;  ///< Z85
};

/// True when `key` is 40 Z85 characters that decode to 32 bytes.
bool isZ85Key(std::string_view key);
/// A new key pair (zmq_curve_keypair). \throws std::runtime_error when libzmq lacks CURVE.
CurveKeyPair generateCurveKeyPair();
/// The public key of a secret key (zmq_curve_public). \throws std::invalid_argument for a bad key.
std::string curvePublicKey(const std::string& secret_z85);
/// 32 binary bytes → Z85 (40 characters).
std::string z85Encode(std::string_view binary32);
/// True when this libzmq supports CURVE (zmq_has("curve")).
bool hasCurve();

/// Reads a key file (see above). `secret` also refuses a file readable by group or others.
/// \throws std::runtime_error "FILE: ..." (missing, unreadable, no key, not a Z85 key, permissions).
std::string readKeyFile(const std::string& path, bool secret);

/// Writes `key` (Z85) to `path` with a comment line, creating it with `mode` (0600 for secrets).
/// Refuses to overwrite. \throws std::runtime_error "FILE: ...".
void writeKeyFile(const std::string& path, const std::string& key, const std::string& comment, unsigned mode);

}  // namespace mannequin::transport
