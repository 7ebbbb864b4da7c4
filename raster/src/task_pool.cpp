#include <raster/task_pool.h>

#include <utility>

namespace raster {

TaskPool::TaskPool(uint32_t threads) : thread_count_(threads) {
    worker_count_ = threads == 0 ? 1 : threads;
    // The caller is worker 0, so threads - 1 extra threads make `threads` workers.
    for (uint32_t w = 1; w < worker_count_; ++w)
        threads_.emplace_back([this, w] { workerLoop(w); });
}

TaskPool::~TaskPool() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_)
        t.join();
}

void TaskPool::drain(uint32_t worker) {
    for (;;) {
        const uint32_t index = next_.fetch_add(1, std::memory_order_relaxed);
        if (index >= job_count_)
            return;
        try {
            (*job_)(index, worker);
        } catch (...) {
            // Stop handing out work; the caller rethrows the first failure.
            next_.store(job_count_, std::memory_order_relaxed);
            std::lock_guard<std::mutex> lock(mutex_);
            if (!failure_)
                failure_ = std::current_exception();
            return;
        }
    }
}

void TaskPool::workerLoop(uint32_t worker) {
    uint64_t seen = 0;
    for (;;) {
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
            if (stop_)
                return;
            seen = generation_;
        }
        drain(worker);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (--busy_ == 0)
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
    {
        std::lock_guard<std::mutex> lock(mutex_);
        job_ = &fn;
        job_count_ = count;
        next_.store(0, std::memory_order_relaxed);
        busy_ = uint32_t(threads_.size());
        ++generation_;
    }
    wake_.notify_all();
    drain(0);
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return busy_ == 0; });
    job_ = nullptr;
    if (failure_)
        std::rethrow_exception(std::exchange(failure_, nullptr));
}

} // namespace raster
