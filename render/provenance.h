// Provenance: which flexure made a file, from which source and by which command. Every JSON
// output carries it as "flexure": {...}, PNG as tEXt, SVG as <metadata>, PDF as Creator and
// Producer. It sits at the bottom of the layers so that every writer can reach it.
#pragma once

#include <string>
#include <vector>

namespace flexure::render {

// The version (CMake's project version), the source's commit (12 hex digits, "-dirty" when the
// tree had changes to tracked files when it was built, "unknown" outside a git checkout) and the
// build type (Release, RelWithDebInfo, ...).
const std::string& flexureVersion();
const std::string& flexureCommit();
const std::string& flexureBuildType();

// The command that is running, word by word: the command line for `flexure`, a
// description such as ["python", "flexure.System.analyze"] for the module. Empty until a front
// end sets it.
void setCommandLine(std::vector<std::string> words);
std::vector<std::string> commandLine();

// "flexure 0.1.0 (commit 0123456789ab, Release)": what the images' metadata carries.
std::string creatorText();

}  // namespace flexure::render
