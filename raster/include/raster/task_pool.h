// TaskPool: a fixed set of std::thread workers, created by the caller and passed down (no
// globals). parallelFor splits the indices into one contiguous share per worker; a worker takes
// its own share from the front and then the others' from their backs (work stealing). Which
// worker runs which index is not deterministic, so callers write each result to a slot owned by
// its index. threads == 0 runs everything inline on the calling thread.
//
// Why shares rather than one counter for all: a frame's buffers are written tile by tile, frame
// after frame (and accum's views into the same frame). With one counter a tile went to either
// worker at random, so about half of every frame's stores hit lines the other core wrote last
// and had to fetch them from it; with shares a worker gets mostly the tiles it had in the last
// frame. Stealing from the back keeps the balance of one counter: a worker idles only when no
// index is left anywhere.
//
// A frame makes tens of parallelFor calls with a little serial work between them. Waking a
// sleeping thread through the kernel costs tens of microseconds (more in a virtual machine), and
// the caller would run alone meanwhile; so a worker that finishes spins for a while before it
// sleeps, and so does the caller waiting for the last worker (not when there are more threads
// than cores). The condition variables are notified only when some thread is asleep on them.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace raster {

// A non-owning reference to a callable `void(uint32_t index, uint32_t worker)`: what
// parallelFor runs. Unlike std::function it never allocates (a lambda capturing more than two
// pointers would, on every call), so a frame's many parallelFor calls allocate nothing. The
// callable must outlive the call it is passed to, as a temporary lambda argument does.
class TaskFn {
public:
    template <class Fn>
    requires(!std::is_same_v<std::remove_cvref_t<Fn>, TaskFn> &&
             std::is_invocable_v<Fn&, uint32_t, uint32_t>)
        TaskFn(Fn&& fn) // NOLINT(google-explicit-constructor): lambdas convert implicitly
        : object_(const_cast<void*>(static_cast<const void*>(std::addressof(fn)))),
          call_([](void* object, uint32_t index, uint32_t worker) {
              (*static_cast<std::remove_reference_t<Fn>*>(object))(index, worker);
          }) {}
    void operator()(uint32_t index, uint32_t worker) const { call_(object_, index, worker); }

private:
    void* object_;
    void (*call_)(void*, uint32_t, uint32_t);
};

class TaskPool {
public:
    explicit TaskPool(uint32_t threads);
    ~TaskPool();
    TaskPool(const TaskPool&) = delete;
    TaskPool& operator=(const TaskPool&) = delete;

    // Number of distinct `worker` values parallelFor passes (>= 1).
    uint32_t workerCount() const { return worker_count_; }
    uint32_t threadCount() const { return thread_count_; }

    // Calls fn(index, worker) once for every index in [0, count); returns when all are done.
    // The calling thread takes part as worker 0. Not reentrant. If fn throws (std::bad_alloc
    // in practice), the remaining indices are skipped and the first exception is rethrown here
    // on the calling thread, instead of ending the process in std::terminate on a worker.
    void parallelFor(uint32_t count, TaskFn fn);

private:
    // One worker's share of the job's indices, [front, back) packed in one word (back in the
    // high half) so that its owner (front) and thieves (back) never take the same index.
    struct alignas(64) Share {
        std::atomic<uint64_t> range{0};
    };

    void workerLoop(uint32_t worker);
    void drain(uint32_t worker);
    void run(uint32_t index, uint32_t worker);

    uint32_t thread_count_ = 0;
    uint32_t worker_count_ = 1;
    std::chrono::microseconds spin_{0}; // how long an idle thread spins before it sleeps
    std::vector<std::thread> threads_;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::condition_variable done_;
    // The job, written by parallelFor before it publishes a new generation (release) and read
    // by the workers after they see it (acquire).
    const TaskFn* job_ = nullptr;
    std::atomic<uint64_t> generation_{0}; // incremented (under mutex_) per job and at shutdown
    std::atomic<uint32_t> busy_{0};       // threads still draining the current job
    std::atomic<bool> stop_{false};
    std::unique_ptr<Share[]> shares_; // worker_count_ entries
    uint32_t sleeping_ = 0;           // threads waiting on wake_ (guarded by mutex_)
    bool caller_waiting_ = false;     // the caller waits on done_ (guarded by mutex_)
    std::exception_ptr failure_;      // the first exception fn threw (guarded by mutex_)
};

} // namespace raster
