// The request a worker thread is serving, from cpp-httplib's pre-routing handler to its
// logger (internal to the service's files).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "http/admission.h"
#include "http/api_keys.h"

namespace effectd {

// Per-request state. A request is served start to finish on one worker thread, from the
// pre-routing handler to the logger, so thread-local storage is the request's scratch pad.
struct RequestState {
  bool active = false;
  std::chrono::steady_clock::time_point start;
  std::string route = "unmatched";
  std::string requestId;
  std::string acceptEncoding;  // taken off the request so cpp-httplib does not encode itself
  std::string corsOrigin;      // the value of Access-Control-Allow-Origin, "" = no CORS headers
  bool encoded = false;        // the answer's coding is chosen (and part of its ETag) already
  std::optional<ApiKey> key;   // the API key the request came with (access.h)
  std::string keyId;           // its id, for the access log
  std::shared_ptr<void> keyPlace;  // one of the key's maxConcurrent places (Access::enter)
  bool keyCharged = false;         // the key has paid the request's units (Access::charge)
  // Held until the answer has been written (the logger runs after that).
  Admission::Ticket bodyTicket, workTicket;
};
extern thread_local RequestState tl;  // the request this thread is serving

// The client's X-Request-ID when it is short and plain, else a fresh random one.
bool saneRequestId(const std::string& id);
std::string newRequestId();
// The media type of a Content-Type value, lower case, without parameters.
std::string mediaType(const std::string& contentType);

}  // namespace effectd
