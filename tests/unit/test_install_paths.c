/* Where an installation's files are looked for (server/cli/install_paths.c): the prefix a
 * binary belongs to, from the folder it runs from and the prefix and bin folder it was built
 * for; and each installed folder under that prefix, or where it was built for when it does
 * not lie under the prefix (/etc and /var for a /usr build). */
#include "check.h"
#include "install_paths.h"

static void check_prefix(const char *exe_dir, const char *prefix, const char *bindir,
                         const char *expected)
{
    char out[256];
    check_case_name = exe_dir;
    CHECK(install_paths_prefix(exe_dir, prefix, bindir, out, sizeof out));
    CHECK_STR(out, expected);
}

static void check_relocate(const char *dir, const char *built, const char *prefix,
                           const char *expected)
{
    char out[256];
    check_case_name = dir;
    CHECK(install_paths_relocate(dir, built, prefix, out, sizeof out));
    CHECK_STR(out, expected);
}

int main(void)
{
    /* At home, moved, and not installed at all (a build tree). */
    check_prefix("/usr/local/bin", "/usr/local", "/usr/local/bin", "/usr/local");
    check_prefix("/usr/local/bin/", "/usr/local/", "/usr/local/bin", "/usr/local/");
    check_prefix("/tmp/p/bin", "/usr/local", "/usr/local/bin", "/tmp/p");
    check_prefix("/opt/skyd/bin", "/usr", "/usr/bin", "/opt/skyd");
    check_prefix("/work/skyd/build", "/usr/local", "/usr/local/bin", "/usr/local");
    check_prefix("/work/skyd/sbin", "/usr/local", "/usr/local/bin", "/usr/local");
    check_prefix("/bin", "/usr/local", "/usr/local/bin", "/");
    /* A bin folder of more than one level, and one outside the prefix: never moved. */
    check_prefix("/tmp/p/lib/skyd/bin", "/usr", "/usr/lib/skyd/bin", "/tmp/p");
    check_prefix("/tmp/p/bin", "/usr", "/srv/bin", "/usr");
    /* The prefix "/" itself. */
    check_prefix("/tmp/p/bin", "/", "/bin", "/tmp/p");

    check_relocate("/usr/local/share/skyd", "/usr/local", "/tmp/p", "/tmp/p/share/skyd");
    check_relocate("/usr/local/etc/skyd", "/usr/local", "/tmp/p/", "/tmp/p/etc/skyd");
    check_relocate("/usr/local/share/skyd", "/usr/local", "/usr/local", "/usr/local/share/skyd");
    check_relocate("/etc/skyd", "/usr", "/opt/skyd", "/etc/skyd");
    check_relocate("/usr/localx/share", "/usr/local", "/tmp/p", "/usr/localx/share");
    check_relocate("/share/skyd", "/", "/tmp/p", "/tmp/p/share/skyd");

    /* Results that do not fit are refused, not cut. */
    char small[8];
    check_case_name = "too small";
    CHECK(!install_paths_prefix("/tmp/prefix/bin", "/usr", "/usr/bin", small, sizeof small));
    CHECK(!install_paths_relocate("/usr/share/skyd", "/usr", "/tmp", small, sizeof small));
    check_case_name = "";
    return check_summary();
}
