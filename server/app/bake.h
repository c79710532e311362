// `effectd bake`: a request baked as a job on an effectd server, with a progress bar (bake.cpp).
#pragma once

#include <string>
#include <vector>

namespace effectd {

// The arguments after `bake`; returns the exit status.
int bakeCommand(const std::vector<std::string>& args);

}  // namespace effectd
