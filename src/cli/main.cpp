#include "commands.h"

int main(int argc, char** argv) { return sift_hull::cli::runMain(argc, argv); }
