#!/usr/bin/env bash
# Formats the C sources with .clang-format: every *.c and *.h under protocol/, render/, server/,
# clients/, tests/ and bench/ (shaders/ is GLSL and is left alone).
#   scripts/format.sh           rewrite the files in place
#   scripts/format.sh --check   change nothing; a non-zero status when a file is not formatted
set -euo pipefail
cd "$(dirname "$0")/.."
clang_format=${CLANG_FORMAT:-clang-format}
mode=(-i)
if [ "${1:-}" = "--check" ]; then
  mode=(--dry-run -Werror)
fi
find protocol render server clients tests bench -name '*.[ch]' -print0 |
  xargs -0 -n 50 "$clang_format" --style=file "${mode[@]}"
