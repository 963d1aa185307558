#include "core/parallel/task_monitor.h"

#include <iostream>

namespace sdf {
namespace {
thread_local TaskMonitor* t_monitor = nullptr;
}

void TaskMonitor::warn(const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex_);
    warnings_.push_back(text);
}

std::vector<std::string> TaskMonitor::take_warnings() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    out.swap(warnings_);
    return out;
}

TaskMonitor* current_task_monitor() { return t_monitor; }

ScopedTaskMonitor::ScopedTaskMonitor(TaskMonitor* monitor) : previous_(t_monitor) { t_monitor = monitor; }
ScopedTaskMonitor::~ScopedTaskMonitor() { t_monitor = previous_; }

void report_warning(const std::string& text) {
    if (TaskMonitor* m = current_task_monitor()) m->warn(text);
    else std::cerr << "warning: " << text << "\n";
}

}  // namespace sdf
