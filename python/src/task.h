/// @file task.h
/// @brief How the module runs a long call: with the GIL released, Ctrl-C honoured within a
/// fraction of a second, progress through a Python callback, and the call's warnings raised
/// through Python's `warnings` (sdf_lattices.SdfWarning) instead of written on C stderr.
///
/// The work (C++ only: it never touches a Python object) runs on a worker thread while the
/// calling thread waits in steps of 0.1 s; between steps it takes the GIL, runs Python's
/// signal handlers (PyErr_CheckSignals) and calls the progress callback. Ctrl-C (or an
/// exception from the callback) asks the work to stop (core/parallel/task_monitor.h): every
/// parallel loop ends at its next chunk, and the Python exception is raised once the worker
/// has ended. Small calls (and collective MPI calls, whose MPI must stay on the main
/// thread) run on the calling thread: same results, no thread to start.
#pragma once

#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "core/parallel/task_monitor.h"
#include "python/src/common.h"

namespace sdf {

struct TaskOptions {
    int64_t total = 0;                    ///< items of the progress bar (points)
    std::string label;                    ///< "querying 'bunny'"
    py::object progress = py::none();     ///< None/False, True (tqdm or text lines), or a callable
    bool background = true;               ///< false: on the calling thread (MPI collectives)
};

/// Work this size or larger runs on a worker thread (Ctrl-C, progress); smaller work on the
/// calling thread, where a worker's start would cost more than the work.
inline constexpr int64_t kBackgroundItems = 4096;

/// The progress reporter of a call: None, or an object with update(done, total) and close()
/// (sdf_lattices._progress.reporter).
py::object progress_reporter(const py::object& progress, const std::string& label, int64_t total);

/// Raises each collected warning as sdf_lattices.SdfWarning.
void raise_warnings(const std::vector<std::string>& warnings);

/// Runs work() as described above and returns its result; rethrows its exception.
template <typename Work>
auto run_task(Work work, const TaskOptions& options) -> decltype(work()) {
    using Result = decltype(work());
    TaskMonitor monitor;
    std::optional<Result> result;
    std::exception_ptr error;
    const bool background = options.background && (options.total >= kBackgroundItems || py::bool_(options.progress));
    if (!background) {
        {
            py::gil_scoped_release release;
            ScopedTaskMonitor scope(&monitor);
            try {
                result.emplace(work());
            } catch (...) {
                error = std::current_exception();
            }
        }
        raise_warnings(monitor.take_warnings());
        if (error) std::rethrow_exception(error);
        return std::move(*result);
    }
    const py::object reporter = progress_reporter(options.progress, options.label, options.total);
    std::mutex mutex;
    std::condition_variable finished_cv;
    bool finished = false;
    std::thread worker([&] {
        ScopedTaskMonitor scope(&monitor);
        try {
            result.emplace(work());
        } catch (...) {
            error = std::current_exception();
        }
        std::lock_guard<std::mutex> lock(mutex);
        finished = true;
        finished_cv.notify_all();
    });
    std::optional<py::error_already_set> python_error;  // Ctrl-C, or the callback's exception
    for (;;) {
        {
            py::gil_scoped_release release;
            std::unique_lock<std::mutex> lock(mutex);
            if (finished_cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return finished; })) break;
        }
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (!reporter.is_none()) reporter.attr("update")(std::min(monitor.done(), options.total), options.total);
        } catch (py::error_already_set& e) {
            python_error.emplace(std::move(e));
            monitor.request_stop();
            break;
        }
    }
    {
        py::gil_scoped_release release;
        worker.join();
    }
    if (!reporter.is_none()) {
        if (!python_error && !error) reporter.attr("update")(options.total, options.total);
        reporter.attr("close")();
    }
    raise_warnings(monitor.take_warnings());
    if (python_error) throw std::move(*python_error);
    if (error) std::rethrow_exception(error);
    return std::move(*result);
}

}  // namespace sdf
