// drift: command-line entry point. Dispatches to one subcommand per file (tools/cmd_*.c),
// listed in DRIFT_COMMAND_LIST (tools/cli.h).
#include "cli.h"

#define DRIFT__COMMAND_ENTRY(name, fn, summary) { name, fn, summary },
static const cli_subcommand commands[] = { DRIFT_COMMAND_LIST(DRIFT__COMMAND_ENTRY) };
#undef DRIFT__COMMAND_ENTRY

int main(int argc, char **argv)
{
    return cli_dispatch(NULL, "commands", "'drift <command> --help' describes each command.\n",
                        commands, sizeof commands / sizeof *commands, argc, argv);
}
