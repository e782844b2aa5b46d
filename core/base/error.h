// Error types that cross module edges: bad input and cancellation.
#pragma once

#include <stdexcept>
#include <string>

namespace sylva {

// Bad input or a failed operation; the message names the file or parameter and the problem.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Thrown by long jobs when their Progress was cancelled.
class Cancelled : public std::runtime_error {
public:
    Cancelled() : std::runtime_error("cancelled") {}
};

} // namespace sylva
