// kernels.cu run on the host: the test device of src/solver/cuda/emulator.rs, built as a
// shared library. Only the CUDA names kernels.cu uses are defined here; the launch
// sequence is the backend's own Rust code, which calls `precursors_emulated_block` for
// each block of a launch, several blocks at once on its threads.
//
// Generated beside this file's build (emulator.rs): kernels_host.cu (kernels.cu with its
// `extern "C"` removed, so that it can be included in several namespaces) and
// kernel_list.inc (`KERNEL(name)` per kernel, in kernels.rs's order: a kernel's index).
//
// Blocks that run at the same time must not share `__shared__` memory, which is a
// function's static variable here: kernels.cu is included once per lane (LANES
// namespaces), and the Rust side runs at most one block per lane at a time.
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

// Threads per block, given as -DTHREADS as NVRTC is given it: 1 (a block is one thread,
// `__syncthreads` a no-op), or more, run as real threads that meet at a barrier for each
// `__syncthreads`, so that a missing or misplaced barrier in a kernel shows.
#ifndef THREADS
#error "compile with -DTHREADS=..."
#endif

struct double2 {
    double x, y;
};
struct Dim {
    unsigned x, y, z;
};
static thread_local Dim threadIdx, blockIdx, blockDim, gridDim;

// A block's threads that do not all reach a barrier within the timeout: the waiting
// ones leave by this exception, and the launch fails instead of hanging.
struct Stuck {};

class Barrier {
  public:
    explicit Barrier(unsigned count) : count_(count) {}
    void wait() {
        std::unique_lock<std::mutex> lock(mutex_);
        if (broken_) throw Stuck{};
        unsigned generation = generation_;
        if (++waiting_ == count_) {
            waiting_ = 0;
            generation_++;
            cv_.notify_all();
            return;
        }
        bool passed = cv_.wait_for(lock, std::chrono::seconds(20),
                                   [&] { return generation_ != generation || broken_; });
        if (!passed || generation_ == generation) {
            broken_ = true;
            cv_.notify_all();
            throw Stuck{};
        }
    }

  private:
    std::mutex mutex_;
    std::condition_variable cv_;
    unsigned count_, waiting_ = 0, generation_ = 0;
    bool broken_ = false;
};

#if THREADS > 1
static thread_local Barrier* block_barrier;
#define __syncthreads() block_barrier->wait()
#else
#define __syncthreads()
#endif
#define __device__
#define __forceinline__ inline
#define __global__
#define __shared__ static
static inline void sincospi(double a, double* s, double* c) {
    long double pi = 3.141592653589793238462643383279502884L;
    *s = (double)std::sin(pi * a);
    *c = (double)std::cos(pi * a);
}
using std::fabs;
using std::fmax;
using std::isfinite;
using std::min;
using std::sqrt;

// A kernel called with cuLaunchKernel's `void** params` (each entry points to its
// argument's value), its parameter types read off its own signature.
template <class... A, std::size_t... I>
static void call_with(void (*kernel)(A...), void** params, std::index_sequence<I...>) {
    kernel(*static_cast<A*>(params[I])...);
}
template <class... A>
static void call(void (*kernel)(A...), void** params) {
    call_with(kernel, params, std::index_sequence_for<A...>{});
}

#define LANE_DISPATCH                                     \
    static bool dispatch(int kernel, void** params) {     \
        int k = 0;                                        \
        (void)k;
#define KERNEL(name)               \
    if (kernel == k++) {           \
        call(name, params);        \
        return true;               \
    }

namespace lane0 {
#include "kernels_host.cu"
LANE_DISPATCH
#include "kernel_list.inc"
return false;
}
}  // namespace lane0
namespace lane1 {
#include "kernels_host.cu"
LANE_DISPATCH
#include "kernel_list.inc"
return false;
}
}  // namespace lane1
namespace lane2 {
#include "kernels_host.cu"
LANE_DISPATCH
#include "kernel_list.inc"
return false;
}
}  // namespace lane2
namespace lane3 {
#include "kernels_host.cu"
LANE_DISPATCH
#include "kernel_list.inc"
return false;
}
}  // namespace lane3

static bool dispatch(int lane, int kernel, void** params) {
    switch (lane) {
        case 0: return lane0::dispatch(kernel, params);
        case 1: return lane1::dispatch(kernel, params);
        case 2: return lane2::dispatch(kernel, params);
        case 3: return lane3::dispatch(kernel, params);
        default: return false;
    }
}

static std::atomic<int> in_flight{0}, most_in_flight{0};

extern "C" {

// The lanes (blocks that may run at once) and the threads per block of this build.
int precursors_emulated_lanes() { return 4; }
int precursors_emulated_threads() { return THREADS; }

// The most blocks that ran at once since the last call (then reset).
int precursors_emulated_most_in_flight() { return most_in_flight.exchange(0); }

// Block `block` of `grid` blocks of `kernel` in `lane`'s copy of the kernels. Returns 0,
// or 1 for an unknown kernel or lane, 2 for threads stuck at a barrier.
int precursors_emulated_block(int lane, int kernel, unsigned grid, unsigned block,
                              void** params) {
    int now = ++in_flight;
    int most = most_in_flight.load();
    while (now > most && !most_in_flight.compare_exchange_weak(most, now)) {
    }
    std::atomic<int> status{0};
    auto run = [&](unsigned t) {
        threadIdx = {t, 0, 0};
        blockIdx = {block, 0, 0};
        blockDim = {THREADS, 1, 1};
        gridDim = {grid, 1, 1};
        try {
            if (!dispatch(lane, kernel, params)) status = 1;
        } catch (Stuck&) {
            status = 2;
        }
    };
#if THREADS > 1
    Barrier barrier(THREADS);
    std::vector<std::thread> threads;
    threads.reserve(THREADS);
    for (unsigned t = 0; t < THREADS; t++)
        threads.emplace_back([&, t] {
            block_barrier = &barrier;
            run(t);
        });
    for (auto& t : threads) t.join();
#else
    run(0);
#endif
    --in_flight;
    return status.load();
}
}
