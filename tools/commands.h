// The subcommands of the siviflow tool; each returns the process exit status.
#pragma once

namespace siviflow {

int run_info(int argc, char** argv);
int run_capture(int argc, char** argv);
int run_flow(int argc, char** argv);
int run_bench(int argc, char** argv);
int run_view(int argc, char** argv);
int run_verify(int argc, char** argv);

}  // namespace siviflow
