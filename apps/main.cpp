#include "apps/cli.h"

int main(int argc, char** argv) {
    return focal::runCli(argc, argv);
}
