// The RESP2 client (redis.h).
#include "http/redis.h"

#include <cctype>
#include <cerrno>
#include <cstdlib>

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace effectd {

namespace {
constexpr size_t kMaxLine = 1 << 16;          // a status, error or length line
constexpr long long kMaxBulk = 512ll << 20;   // Redis's own limit on a string
constexpr int kMaxDepth = 8;                  // nested arrays

std::string percentDecoded(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += char(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}
// A command as RESP: an array of bulk strings.
std::string encoded(const std::vector<std::string>& args) {
  std::string out = "*" + std::to_string(args.size()) + "\r\n";
  for (const auto& a : args) out += "$" + std::to_string(a.size()) + "\r\n" + a + "\r\n";
  return out;
}
}  // namespace

RedisClient::RedisClient(const std::string& url, std::chrono::milliseconds timeout, std::chrono::milliseconds retry)
    : timeout_(timeout), retry_(retry) {
  std::string rest = url.rfind("redis://", 0) == 0 ? url.substr(8) : url;
  const size_t slash = rest.find('/');
  if (slash != std::string::npos) rest.resize(slash);
  if (const size_t at = rest.rfind('@'); at != std::string::npos) {
    const std::string userinfo = rest.substr(0, at);
    const size_t colon = userinfo.find(':');
    user_ = percentDecoded(colon == std::string::npos ? "" : userinfo.substr(0, colon));
    password_ = percentDecoded(colon == std::string::npos ? userinfo : userinfo.substr(colon + 1));
    rest.erase(0, at + 1);
  }
  const size_t colon = rest.rfind(':');
  host_ = colon == std::string::npos ? rest : rest.substr(0, colon);
  port_ = colon == std::string::npos ? "6379" : rest.substr(colon + 1);
}

RedisClient::~RedisClient() { disconnect(); }

std::optional<RedisReply> RedisClient::command(const std::vector<std::string>& args) {
  std::lock_guard lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  if (fd_ < 0 && now < retryAt_) return std::nullopt;
  const std::string request = encoded(args);
  RedisReply reply;
  const bool answered = (fd_ >= 0 || connect()) && send(request) && readReply(reply, 0);
  std::string problem;
  if (answered) {
    buffer_.erase(0, read_);
    read_ = 0;
    if (reply.type == RedisReply::Type::kError) problem = "answers " + reply.text + " at " + address();
  } else {
    disconnect();
    retryAt_ = now + retry_;
    ++failures_;
    problem = refused_.empty() ? "unreachable at " + address() : "refused AUTH at " + address() + ": " + refused_;
  }
  {
    std::lock_guard state(problemMutex_);
    problem_ = problem;
  }
  if (!answered) return std::nullopt;
  return reply;
}

std::string RedisClient::problem() {
  command({"PING"});
  return lastProblem();
}

std::string RedisClient::lastProblem() const {
  std::lock_guard lock(problemMutex_);
  return problem_;
}

bool RedisClient::connect() {
  refused_.clear();  // a refusal is this connection's, not the last one's
  addrinfo hints{}, *found = nullptr;
  hints.ai_socktype = SOCK_STREAM;
  if (getaddrinfo(host_.c_str(), port_.c_str(), &hints, &found) != 0 || !found) return false;
  fd_ = ::socket(found->ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  bool ok = fd_ >= 0;
  if (ok && ::connect(fd_, found->ai_addr, found->ai_addrlen) != 0) {
    pollfd p{fd_, POLLOUT, 0};
    int error = 0;
    socklen_t length = sizeof error;
    ok = errno == EINPROGRESS && ::poll(&p, 1, int(timeout_.count())) == 1 &&
         ::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &length) == 0 && error == 0;
  }
  freeaddrinfo(found);
  if (ok) {
    int one = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    ok = authenticate();
  }
  if (!ok) disconnect();
  return ok;
}

bool RedisClient::authenticate() {
  if (password_.empty()) return true;
  std::vector<std::string> args{"AUTH"};
  if (!user_.empty()) args.push_back(user_);
  args.push_back(password_);
  const std::string request = encoded(args);
  RedisReply reply;
  if (!send(request) || !readReply(reply, 0)) return false;
  buffer_.erase(0, read_);
  read_ = 0;
  if (reply.type == RedisReply::Type::kError) refused_ = reply.text;
  return refused_.empty();
}

void RedisClient::disconnect() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  buffer_.clear();
  read_ = 0;
}

bool RedisClient::send(const std::string& bytes) {
  for (size_t done = 0; done < bytes.size();) {
    pollfd p{fd_, POLLOUT, 0};
    if (::poll(&p, 1, int(timeout_.count())) != 1) return false;
    const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

bool RedisClient::fill() {
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, int(timeout_.count())) != 1) return false;
  char chunk[65536];
  const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
  if (n <= 0) return false;
  buffer_.append(chunk, size_t(n));
  return true;
}

bool RedisClient::readLine(std::string& line) {
  for (;;) {
    const size_t end = buffer_.find("\r\n", read_);
    if (end != std::string::npos) {
      line = buffer_.substr(read_, end - read_);
      read_ = end + 2;
      return true;
    }
    if (buffer_.size() - read_ > kMaxLine || !fill()) return false;
  }
}

bool RedisClient::readReply(RedisReply& reply, int depth) {
  std::string line;
  if (depth > kMaxDepth || !readLine(line) || line.empty()) return false;
  const char kind = line[0];
  const std::string rest = line.substr(1);
  char* end = nullptr;
  const long long n = std::strtoll(rest.c_str(), &end, 10);
  const bool number = !rest.empty() && end && *end == '\0';
  switch (kind) {
    case '+': reply.type = RedisReply::Type::kString, reply.text = rest; return true;
    case '-': reply.type = RedisReply::Type::kError, reply.text = rest; return true;
    case ':':
      reply.type = RedisReply::Type::kInteger, reply.integer = n;
      return number;
    case '$': {
      if (!number || n > kMaxBulk) return false;
      if (n < 0) return reply.type = RedisReply::Type::kNil, true;
      while (buffer_.size() - read_ < size_t(n) + 2)
        if (!fill()) return false;
      reply.type = RedisReply::Type::kString;
      reply.text = buffer_.substr(read_, size_t(n));
      read_ += size_t(n) + 2;
      return true;
    }
    case '*': {
      if (!number || n > (1 << 20)) return false;
      if (n < 0) return reply.type = RedisReply::Type::kNil, true;
      reply.type = RedisReply::Type::kArray;
      reply.items.resize(size_t(n));
      for (RedisReply& item : reply.items)
        if (!readReply(item, depth + 1)) return false;
      return true;
    }
    default: return false;
  }
}

}  // namespace effectd
