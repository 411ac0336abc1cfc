// Errors a user can cause (bad scene, bad option, unwritable output). The CLI turns them into a
// message naming the file and the problem, and exit code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace bdptref {

class InputError : public std::runtime_error {
public:
    explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace bdptref
