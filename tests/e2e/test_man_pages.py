#!/usr/bin/python3
"""The manual pages in docs/man against the programs they describe.

Usage: /usr/bin/python3 tests/e2e/test_man_pages.py SKYD SKYCTL MAN_DIR

- Each page renders without a warning from man/groff (the check lintian makes).
- skyd.1 names every option that `skyd --help` and `skyd serve|render|probe|metar|forecast
  --help` list, and names no option that none of them lists; skyctl.1 the same for `skyctl --help`.
- skyd.json.5 names every member of the configuration's schema (`skyd schema config`), and
  every member it names as a dotted path is one.
Exit 0 when every check passed.
"""

import json
import os
import re
import subprocess
import sys

failures = 0
checks = 0


def check(name, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print(f"FAIL: {name}" + (f": {detail}" if detail else ""))


def page_text(path):
    """The page's source with roff escapes for hyphens and fonts taken out."""
    text = open(path, encoding="utf-8").read()
    text = re.sub(r"\\f[BIRP]", "", text)
    return text.replace("\\-", "-").replace("\\e", "\\")


OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def options_of(text):
    return set(OPTION.findall(text))


def help_text(argv):
    r = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    check(f"{' '.join(argv)} exits 0", r.returncode == 0, r.stderr[-500:])
    return r.stdout + r.stderr


def config_members(schema, prefix=""):
    for name, member in schema.get("properties", {}).items():
        if member.get("type") == "object" and "properties" in member and name != "initial_state":
            yield from config_members(member, prefix + name + ".")
        else:
            yield prefix + name


def main():
    skyd, skyctl, man_dir = sys.argv[1:4]
    pages = {name: os.path.join(man_dir, name) for name in ("skyd.1", "skyctl.1", "skyd.json.5")}
    env = dict(os.environ, LC_ALL="C.UTF-8", MANROFFSEQ="", MANWIDTH="80")
    for name, path in pages.items():
        r = subprocess.run(["man", "--warnings", "-E", "UTF-8", "-l", "-Tutf8", "-Z", path],
                           capture_output=True, text=True, env=env, timeout=60)
        check(f"{name} renders without warnings", r.returncode == 0 and not r.stderr.strip(),
              r.stderr.strip()[:800])

    skyd_help = "".join(help_text([skyd] + args) for args in
                        (["--help"], ["serve", "--help"], ["render", "--help"],
                         ["probe", "--help"], ["metar", "--help"], ["forecast", "--help"]))
    for name, told in (("skyd.1", options_of(skyd_help)),
                       ("skyctl.1", options_of(help_text([skyctl, "--help"])))):
        documented = options_of(page_text(pages[name]))
        check(f"{name} names every option of --help", told <= documented,
              " ".join(sorted(told - documented)))
        check(f"{name} names no option --help does not list", documented <= told,
              " ".join(sorted(documented - told)))

    r = subprocess.run([skyd, "schema", "config"], capture_output=True, text=True, timeout=60)
    members = set(config_members(json.loads(r.stdout)))
    check("skyd schema config lists members", len(members) > 10, str(sorted(members)))
    # The MEMBERS section's tags: the line after each .TP, e.g. `.BR limits.max_width ", " ...`.
    text = page_text(pages["skyd.json.5"])
    section = text.split(".SH MEMBERS", 1)[-1].split("\n.SH ", 1)[0].splitlines()
    named = set()
    for before, line in zip(section, section[1:]):
        if before.strip() == ".TP":
            named |= set(re.findall(r"(?<![\w.])[a-z_]+(?:\.[a-z_]+)?(?![\w.])",
                                    line.split(" ", 1)[-1]))
    check("skyd.json.5 names every member of the schema", members <= named,
          " ".join(sorted(members - named)))
    check("skyd.json.5 names no member the schema lacks", named <= members,
          " ".join(sorted(named - members)))

    print(f"man pages: {checks - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
