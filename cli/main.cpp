// flexure and flexure-draw: continuous motions of geometric constraint systems (cli/cli.h).
#include "cli/cli.h"

int main(int argc, char** argv) { return flexure::cli::main(argc, argv); }
