// avs: the command line. Subcommands live in their own files (launch.cpp, topic.cpp, ...).
#include <cstdio>

int main() {
  std::fprintf(stderr, "avs: not built yet\n");
  return 1;
}
