// sylva: the command line entry point.
#include <cstdio>

int main()
{
    std::puts("sylva");
    return 0;
}
