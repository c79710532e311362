#include "http/admission.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>

#include "contract/problem.h"

namespace effectd {

Admission::Ticket& Admission::Ticket::operator=(Ticket&& other) noexcept {
  if (this != &other) {
    release();
    owner_ = other.owner_;
    bytes_ = other.bytes_;
    heavy_ = other.heavy_;
    other.owner_ = nullptr;
  }
  return *this;
}

void Admission::Ticket::release() {
  if (owner_) owner_->release(bytes_, heavy_);
  owner_ = nullptr;
}

bool Admission::fits(size_t bytes, bool heavy) const {
  return c_.reservedBytes + bytes <= o_.budgetBytes && (!heavy || c_.heavyRunning < o_.heavySlots);
}

Admission::Ticket Admission::admit(size_t bytes, bool heavy) {
  auto mb = [](size_t b) { return std::to_string((b + (1 << 20) - 1) >> 20) + " MB"; };
  std::unique_lock<std::mutex> lock(mu_);
  if (bytes > o_.budgetBytes) {
    ++c_.refusedTooLarge;
    throw ApiError{413,
                   "over-memory-budget",
                   "Request exceeds the memory budget",
                   "this request needs about " + mb(bytes) +
                       " at its peak, more than the server's whole memory budget of " + mb(o_.budgetBytes) +
                       " (--memory-budget-mb); make it smaller",
                   {},
                   {}};
  }
  auto busy = [&](const std::string& why) {
    ++c_.refusedBusy;
    return ApiError{503, "busy", "Server busy", why + "; retry shortly", {}, {{"Retry-After", "1"}}};
  };
  std::deque<uint64_t>& queue = queue_[heavy ? 1 : 0];
  if (queue.empty() && fits(bytes, heavy)) {
    // Admitted at once.
  } else {
    if (int(queue_[0].size() + queue_[1].size()) >= o_.maxWaiting)
      throw busy("the admission queue is full (" + std::to_string(o_.maxWaiting) +
                 " requests wait for memory or a heavy slot)");
    const uint64_t id = nextId_++;
    queue.push_back(id);
    ++c_.waited;
    c_.waiting = int(queue_[0].size() + queue_[1].size());
    bool ok = cv_.wait_for(lock, o_.maxWait, [&] { return queue.front() == id && fits(bytes, heavy); });
    queue.erase(std::find(queue.begin(), queue.end(), id));
    c_.waiting = int(queue_[0].size() + queue_[1].size());
    cv_.notify_all();  // the next in line may fit now
    if (!ok)
      throw busy("waited " + std::to_string(o_.maxWait.count()) + " ms for " + mb(bytes) +
                 (heavy ? " and a heavy-work slot" : "") + " of the " + mb(o_.budgetBytes) + " memory budget");
  }
  c_.reservedBytes += bytes;
  c_.peakReservedBytes = std::max(c_.peakReservedBytes, c_.reservedBytes);
  if (heavy) ++c_.heavyRunning;
  ++c_.admitted;
  Ticket t;
  t.owner_ = this;
  t.bytes_ = bytes;
  t.heavy_ = heavy;
  return t;
}

void Admission::release(size_t bytes, bool heavy) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    c_.reservedBytes -= bytes;
    if (heavy) --c_.heavyRunning;
  }
  cv_.notify_all();
}

Admission::Counts Admission::counts() const {
  std::lock_guard<std::mutex> lock(mu_);
  Counts c = c_;
  c.budgetBytes = o_.budgetBytes;
  c.maxWaiting = o_.maxWaiting;
  return c;
}

bool Admission::queueFull() const {
  std::lock_guard<std::mutex> lock(mu_);
  return int(queue_[0].size() + queue_[1].size()) >= o_.maxWaiting;
}

namespace {
// A number of bytes from a cgroup file; 0 for "max", absurd values (v1's "no limit" is
// 2^63 rounded to pages) or an unreadable file.
size_t readLimit(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text == "max") return 0;
  char* end = nullptr;
  unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (*end != '\0' || v == 0 || v >= (1ULL << 60)) return 0;
  return size_t(v);
}
}  // namespace

MemoryLimit detectMemoryLimit() {
  const size_t physical = size_t(sysconf(_SC_PHYS_PAGES)) * size_t(sysconf(_SC_PAGESIZE));
  if (size_t v = readLimit("/sys/fs/cgroup/memory.max"); v && v < physical) return {v, "cgroup v2 memory.max"};
  if (size_t v = readLimit("/sys/fs/cgroup/memory/memory.limit_in_bytes"); v && v < physical)
    return {v, "cgroup v1 memory.limit_in_bytes"};
  return {physical, "physical memory"};
}

}  // namespace effectd
