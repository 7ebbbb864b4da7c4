#include <raster/task_pool.h>

#include <chrono>
#include <utility>

namespace raster {

// How long a thread spins for the next job (a worker) or the last worker (the caller) before
// it sleeps: longer than the serial work between most of a frame's parallelFor calls, short
// enough that an idle pool soon stops taking a core.
constexpr auto kSpin = std::chrono::microseconds(200);

TaskPool::TaskPool(uint32_t threads) : thread_count_(threads) {
    worker_count_ = threads == 0 ? 1 : threads;
    shares_ = std::make_unique<Share[]>(worker_count_);
    // More threads than cores: a spinning thread would take the core a working one needs.
    const unsigned cores = std::thread::hardware_concurrency();
    spin_ = cores == 0 || worker_count_ <= cores ? kSpin : std::chrono::microseconds(0);
    // The caller is worker 0, so threads - 1 extra threads make `threads` workers.
    for (uint32_t w = 1; w < worker_count_; ++w)
        threads_.emplace_back([this, w] { workerLoop(w); });
}

TaskPool::~TaskPool() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_.store(true, std::memory_order_relaxed);
        generation_.fetch_add(1, std::memory_order_release);
    }
    wake_.notify_all();
    for (std::thread& t : threads_)
        t.join();
}

namespace {

// Spins until done() or `spin` has passed; returns done().
template <class Done> bool spinUntil(std::chrono::microseconds spin, Done&& done) {
    const auto until = std::chrono::steady_clock::now() + spin;
    for (;;) {
        for (int i = 0; i < 64; ++i) {
            if (done())
                return true;
#if defined(__x86_64__) || defined(__i386__)
            __builtin_ia32_pause();
#endif
        }
        if (std::chrono::steady_clock::now() >= until)
            return done();
    }
}

constexpr uint64_t kBackOne = uint64_t{1} << 32;

uint64_t packRange(uint32_t front, uint32_t back) {
    return uint64_t{back} << 32 | front;
}

// Takes the front (owner) or back (thief) index of a share; false when it is empty.
template <bool kFront> bool take(std::atomic<uint64_t>& range, uint32_t& index) {
    uint64_t r = range.load(std::memory_order_relaxed);
    for (;;) {
        const uint32_t front = uint32_t(r), back = uint32_t(r >> 32);
        if (front >= back)
            return false;
        if (range.compare_exchange_weak(r, kFront ? r + 1 : r - kBackOne,
                                        std::memory_order_relaxed)) {
            index = kFront ? front : back - 1;
            return true;
        }
    }
}

} // namespace

void TaskPool::run(uint32_t index, uint32_t worker) {
    try {
        (*job_)(index, worker);
    } catch (...) {
        // Stop handing out work; the caller rethrows the first failure.
        for (uint32_t w = 0; w < worker_count_; ++w)
            shares_[w].range.store(0, std::memory_order_relaxed);
        std::lock_guard<std::mutex> lock(mutex_);
        if (!failure_)
            failure_ = std::current_exception();
    }
}

void TaskPool::drain(uint32_t worker) {
    uint32_t index = 0;
    while (take<true>(shares_[worker].range, index))
        run(index, worker);
    for (uint32_t i = 1; i < worker_count_; ++i) {
        std::atomic<uint64_t>& victim = shares_[(worker + i) % worker_count_].range;
        while (take<false>(victim, index))
            run(index, worker);
    }
}

void TaskPool::workerLoop(uint32_t worker) {
    uint64_t seen = 0;
    const auto fresh = [&] { return generation_.load(std::memory_order_acquire) != seen; };
    for (;;) {
        if (!spinUntil(spin_, fresh)) {
            std::unique_lock<std::mutex> lock(mutex_);
            ++sleeping_;
            wake_.wait(lock, fresh);
            --sleeping_;
        }
        seen = generation_.load(std::memory_order_acquire);
        if (stop_.load(std::memory_order_relaxed))
            return;
        drain(worker);
        if (busy_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
            std::lock_guard<std::mutex> lock(mutex_);
            if (caller_waiting_)
                done_.notify_all();
        }
    }
}

void TaskPool::parallelFor(uint32_t count, TaskFn fn) {
    if (count == 0)
        return;
    if (threads_.empty() || count == 1) {
        for (uint32_t i = 0; i < count; ++i)
            fn(i, 0);
        return;
    }
    bool wake = false;
    job_ = &fn;
    for (uint32_t w = 0; w < worker_count_; ++w)
        shares_[w].range.store(packRange(uint32_t(uint64_t(count) * w / worker_count_),
                                         uint32_t(uint64_t(count) * (w + 1) / worker_count_)),
                               std::memory_order_relaxed);
    busy_.store(uint32_t(threads_.size()), std::memory_order_relaxed);
    {
        // Published under the lock, so a worker that is about to sleep sees it in its wait.
        std::lock_guard<std::mutex> lock(mutex_);
        generation_.fetch_add(1, std::memory_order_release);
        wake = sleeping_ > 0;
    }
    if (wake)
        wake_.notify_all();
    drain(0);
    const auto finished = [&] { return busy_.load(std::memory_order_acquire) == 0; };
    if (!spinUntil(spin_, finished)) {
        std::unique_lock<std::mutex> lock(mutex_);
        caller_waiting_ = true;
        done_.wait(lock, finished);
        caller_waiting_ = false;
    }
    job_ = nullptr;
    std::exception_ptr failure;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        failure = std::exchange(failure_, nullptr);
    }
    if (failure)
        std::rethrow_exception(failure);
}

} // namespace raster
