/* veil — what the subcommands share: messages, exit codes, option parsing. */
#ifndef VEIL_CLI_UTIL_H
#define VEIL_CLI_UTIL_H

#include "core/result.h"

enum { EXIT_OK = 0, EXIT_INPUT = 1, EXIT_USAGE = 2, EXIT_GPU = 3 };

/* "veil: " + fmt with arg + a hint to --help, on stderr; returns EXIT_USAGE. */
int veil_cli_usage_error(const char* fmt, const char* arg);
/* EXIT_GPU for GPU and shader errors, EXIT_INPUT for the rest. */
int veil_cli_exit_code(veil_result r);
/* Prints err's message (or r's generic one); returns veil_cli_exit_code(r). */
int veil_cli_fail(veil_result r, const veil_error* err);
/* "what went wrong" -> "file: what went wrong". */
void veil_cli_prefix_error(veil_error* err, const char* file);
/* A whole decimal integer in [lo, hi] / a number in [lo, hi]: 1, else 0. */
int veil_cli_parse_int(const char* s, long lo, long hi, long* out);
int veil_cli_parse_float(const char* s, float lo, float hi, float* out);
/* VEIL_ERR_IO naming the path when the folder it would be written to does
 * not exist (checked before any work, so nothing is written half). */
veil_result veil_cli_check_output_folder(const char* path, veil_error* err);

#endif
