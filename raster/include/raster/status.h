// Status and Result: how expected failures at the edges (files, glTF, options, budgets) travel
// back to the caller. Nothing in the core throws across its API; a failed Status carries one
// line the user can act on, e.g. "scene.gltf: accessor 7 reads past the end of buffer 0".
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace raster {

class [[nodiscard]] Status {
public:
    Status() = default;
    static Status error(std::string message) {
        Status s;
        s.message_ = std::move(message);
        s.failed_ = true;
        return s;
    }
    bool ok() const { return !failed_; }
    const std::string& message() const { return message_; }

private:
    std::string message_;
    bool failed_ = false;
};

// Holds a value or the Status explaining why there is none.
template <class T> class [[nodiscard]] Result {
public:
    Result(T value) : value_(std::move(value)) {}         // NOLINT(google-explicit-constructor)
    Result(Status status) : status_(std::move(status)) {} // NOLINT(google-explicit-constructor)
    bool ok() const { return value_.has_value(); }
    const Status& status() const { return status_; }
    T& value() { return *value_; }
    const T& value() const { return *value_; }
    T* operator->() { return &*value_; }
    const T* operator->() const { return &*value_; }
    T& operator*() { return *value_; }
    const T& operator*() const { return *value_; }

private:
    std::optional<T> value_;
    Status status_;
};

} // namespace raster
