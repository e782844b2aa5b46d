// What the --mpi commands share (mpi_session.cpp): MPI's start with the build check, the end of a
// failed job, MPI error codes as exceptions. No MPI header here.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace sylva::mpi {

// MPI_Init (MPI_THREAD_FUNNELED, errors returned), the build check (ranks running another executable
// than rank 0 are refused, exit 1), body(rank, size, each rank's host), MPI_Finalize. Returns body's
// code. `command` names the job in messages ("sylva light: error: ..."), `notWritten` what a failed
// job leaves unwritten ("no picture was written"). Throws Error when the process was not started by
// mpirun. A start (MPI_Init and the build check) that has not finished within 2 x timeoutSeconds + 5 s
// (a rank hung or never started) ends this process with exit 1 and says so; mpirun stops the others.
int runSession(const char* command, const char* notWritten,
               const std::function<int(int rank, int size, const std::vector<std::string>& hosts)>& body, double timeoutSeconds);

// Reports `message` on stderr as the session's error and ends every rank of the job (MPI_Abort, exit 1).
[[noreturn]] void endJob(const std::string& message);

// Throws Error naming `what` and MPI's text when rc is not MPI_SUCCESS.
void checkMpi(int rc, const char* what);

// This machine's host name.
std::string thisHost();

} // namespace sylva::mpi
