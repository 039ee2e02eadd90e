#include "interrupt.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>

namespace loam {

namespace {

volatile std::sig_atomic_t g_signal = 0;

// Fixed storage the handler can read without allocating (only unlink and _exit run in it,
// both async-signal-safe).
constexpr int kSlots = 64;
constexpr size_t kPath = 4096;
char g_temporary[kSlots][kPath];
std::mutex g_temporary_mutex;

extern "C" void on_interrupt(int sig) {
  if (g_signal == 0) {
    g_signal = sig;
    return;
  }
  for (auto& path : g_temporary)
    if (path[0]) unlink(path);
  _exit(128 + sig);
}

struct sigaction g_previous_int, g_previous_term, g_previous_xfsz;

}  // namespace

InterruptGuard::InterruptGuard() {
  g_signal = 0;
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_previous_int);
  sigaction(SIGTERM, &sa, &g_previous_term);
  // A file size limit (ulimit -f) then fails the write with EFBIG, reported as a WriteError,
  // instead of killing the process.
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, &g_previous_xfsz);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
  sigaction(SIGXFSZ, &g_previous_xfsz, nullptr);
}

int InterruptGuard::requested() {
  return g_signal;
}

// A slot is live while its first byte is set: the rest of the path is written first and the
// first byte last (and cleared first), so the handler never reads a half-written path.
void register_temporary_file(const std::string& path) {
  if (path.empty() || path.size() >= kPath) return;
  std::lock_guard<std::mutex> lock(g_temporary_mutex);
  for (auto& slot : g_temporary)
    if (!slot[0]) {
      std::memcpy(slot + 1, path.c_str() + 1, path.size());
      std::atomic_signal_fence(std::memory_order_seq_cst);
      slot[0] = path[0];
      return;
    }
}

void unregister_temporary_file(const std::string& path) {
  std::lock_guard<std::mutex> lock(g_temporary_mutex);
  for (auto& slot : g_temporary)
    if (slot[0] && path == slot) {
      slot[0] = '\0';
      std::atomic_signal_fence(std::memory_order_seq_cst);
      return;
    }
}

std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace loam
