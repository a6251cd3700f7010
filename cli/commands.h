/* veil — subcommands that live in their own files (cli/main.c dispatches).
 * Each returns the process exit code: 0 success, 1 bad input, 2 usage,
 * 3 GPU or driver failure. argv[0] is "veil", argv[1] the subcommand. */
#ifndef VEIL_CLI_COMMANDS_H
#define VEIL_CLI_COMMANDS_H

int veil_cmd_compare(int argc, char** argv);
int veil_cmd_fog(int argc, char** argv);
int veil_cmd_gpuinfo(int argc, char** argv);
int veil_cmd_info(int argc, char** argv);
int veil_cmd_rbf(int argc, char** argv);
int veil_cmd_render(int argc, char** argv);
int veil_cmd_reference(int argc, char** argv);
int veil_cmd_turntable(int argc, char** argv);

#endif
