// Distribution: under an MPI launcher the module starts MPI at import and sample() is
// collective (harness/distributed/distributed.h; docs/distributed.md, "From Python").
#include "harness/distributed/distributed.h"
#include "python/src/common.h"

namespace sdf {

void bind_distributed(py::module_& m) {
    // Under an MPI launcher every rank imports the module: it starts MPI (unless mpi4py or
    // another library did) and ends it at exit, as run-experiment does in main().
    if (start_collective_distribution() == "sdf_lattices") {
        py::module_::import("atexit").attr("register")(py::cpp_function([] {
            py::gil_scoped_release release;
            finish_collective_distribution();
        }));
        // A rank that ends with an uncaught exception would wait in MPI_Finalize for ranks
        // that wait for it: after the traceback, it ends every rank (as `python3 -m mpi4py`).
        if (distributed_active()) {
            py::module_ sys = py::module_::import("sys");
            const py::object previous = sys.attr("excepthook");
            sys.attr("excepthook") = py::cpp_function([previous](py::object type, py::object value, py::object traceback) {
                previous(type, value, traceback);
                py::module_ sys = py::module_::import("sys");
                for (const char* stream : {"stdout", "stderr"})
                    if (!sys.attr(stream).is_none()) sys.attr(stream).attr("flush")();
                abort_distributed(1);
            });
        }
    }
    m.def("distributed", [] { return json_to_python(distributed_info()); },
          R"(distributed() -> dict

This process's place in an MPI run: mpi (whether the module was built with MPI), started_by
("sdf_lattices" when the module started MPI, "another library" when it found MPI running,
e.g. started by mpi4py, None when there is no MPI), rank, size, host, and under MPI
local_rank, local_size (the ranks on this host), threads (each rank's share of the host's
cores, used for threads=0), gpus_on_host and gpu; on rank 0 of several, processes: every
rank's description. The module starts MPI at import when an MPI launcher's environment is
present (mpirun, mpiexec, srun) and ends it at exit, so every rank must import it.)");

}

}  // namespace sdf
