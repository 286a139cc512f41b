#!/usr/bin/python3
"""The cloud noise kept between runs (render/clouds/cloud_noise_cache.h), through `skyd render`.

Usage: /usr/bin/python3 tests/e2e/test_noise_cache.py PATH_TO_SKYD SCRATCH_DIR

- Without a cache (SKYD_CACHE_DIR set but empty) the noise is generated and nothing is written.
- With an empty cache directory (made by skyd, two levels deep) the first render generates the
  noise and leaves one file of the expected size; the second reads it ("cloud noise read from
  the cache", no generation) and its image is byte for byte the generated one's.
- A file with a flipped payload byte, one cut short and one with another seed's header are
  each reported at warning level ("checksum does not match", "is short", "header does not
  match"), the noise is generated, the image is the same, and the file is whole again after.
- More than CLOUD_NOISE_CACHE_FILES (8) files: storing another seed's removes the oldest, not
  the newest ones.
- A directory that cannot be made: a warning naming it, and the render still succeeds.
Exit 0 when every check passed.
"""

import glob
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import check, daemon_environment, summary  # noqa: E402

KEPT_FILES = 8  # CLOUD_NOISE_CACHE_FILES
HEADER_BYTES = 32
# 128^3 and 32^3 RGBA8 volumes, a 128^2 RGBA32F curl texture, the header and the checksum.
FILE_BYTES = HEADER_BYTES + 128 ** 3 * 4 + 32 ** 3 * 4 + 128 ** 2 * 16 + 8
ARGS = ["--weather", "broken", "--width", "96", "--height", "54", "--sun-elevation", "25"]


def render(skyd, scratch, name, cache_dir, extra=()):
    """Renders ARGS (and extra) with SKYD_CACHE_DIR=cache_dir; returns (bytes, stderr, s)."""
    out = os.path.join(scratch, f"{name}.png")
    env = daemon_environment()
    env["SKYD_CACHE_DIR"] = cache_dir
    started = time.monotonic()
    p = subprocess.run([skyd, "render", *ARGS, *extra, "--out", out], env=env,
                       stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True, timeout=300)
    took = time.monotonic() - started
    check(f"{name}: skyd render exits 0", p.returncode == 0, p.stderr[-800:])
    image = b""
    if os.path.exists(out):
        with open(out, "rb") as f:
            image = f.read()
    print(f"  {name}: {took:.1f} s")
    return image, p.stderr, took


def cache_files(directory):
    return sorted(glob.glob(os.path.join(directory, "cloud-noise-*.bin")))


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    skyd, scratch = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    shutil.rmtree(scratch, ignore_errors=True)
    os.makedirs(scratch)
    started = time.monotonic()

    reference, err, _ = render(skyd, scratch, "uncached", "")
    check("no cache: the noise is generated", "cloud noise 100%" in err, err[-400:])
    check("no cache: nothing said of a cache", "cache" not in err, err[-400:])
    check("a PNG came out", reference.startswith(b"\x89PNG"), repr(reference[:16]))

    cache = os.path.join(scratch, "cache", "skyd")
    image, err, generate_s = render(skyd, scratch, "first", cache)
    files = cache_files(cache)
    check("first: the noise is generated", "cloud noise 100%" in err, err[-400:])
    check("first: one file in the directory skyd made", len(files) == 1, str(files))
    check("first: the file holds the three volumes",
          bool(files) and os.path.getsize(files[0]) == FILE_BYTES,
          f"{os.path.getsize(files[0]) if files else 0} bytes, expected {FILE_BYTES}")
    check("first: the image is the uncached one's", image == reference)
    check("no temporary file is left", not glob.glob(os.path.join(cache, "*.tmp")),
          str(os.listdir(cache)))

    image, err, read_s = render(skyd, scratch, "second", cache)
    check("second: the noise is read from the cache",
          f"cloud noise read from the cache in {cache}" in err and "cloud noise 100%" not in err,
          err[-400:])
    check("second: the image is the generated noise's, byte for byte", image == reference)
    print(f"  a render generating the noise took {generate_s:.1f} s, one reading it "
          f"{read_s:.1f} s")

    path = files[0] if files else os.path.join(cache, "missing")
    with open(path, "rb") as f:
        whole = bytearray(f.read())
    damaged = bytearray(whole)
    damaged[HEADER_BYTES + len(whole) // 2] ^= 0x40
    other_seed = bytearray(whole)
    other_seed[12] ^= 0x01  # the header's seed
    for name, content, why in (("flipped", damaged, "its checksum does not match"),
                               ("short", whole[: len(whole) // 3], "it is short"),
                               ("seed", other_seed, "its header does not match")):
        with open(path, "wb") as f:
            f.write(content)
        image, err, _ = render(skyd, scratch, name, cache)
        check(f"{name}: a warning says why the file is not used",
              f"cloud noise cache {path}: {why}" in err, err[-400:])
        check(f"{name}: the noise is generated", "cloud noise 100%" in err, err[-400:])
        check(f"{name}: the image is the same", image == reference)
        with open(path, "rb") as f:
            check(f"{name}: the file is whole again", f.read() == bytes(whole))

    # Stale files of other keys, older than the real one; another seed's noise is then stored.
    now = time.time()
    for k in range(KEPT_FILES):
        stale = os.path.join(cache, f"cloud-noise-{k:016x}.bin")
        with open(stale, "wb") as f:
            f.write(b"stale")
        os.utime(stale, (now - 3600 + k, now - 3600 + k))
    os.utime(path, (now - 60, now - 60))
    image, err, _ = render(skyd, scratch, "other_seed", cache, ["--set", "clouds.noise_seed=7"])
    files = cache_files(cache)
    check(f"another seed: {KEPT_FILES} files are kept", len(files) == KEPT_FILES, str(files))
    check("another seed: the oldest went first",
          not os.path.exists(os.path.join(cache, f"cloud-noise-{0:016x}.bin")) and
          not os.path.exists(os.path.join(cache, f"cloud-noise-{1:016x}.bin")) and
          os.path.exists(os.path.join(cache, f"cloud-noise-{2:016x}.bin")), str(files))
    check("another seed: the first seed's file is kept", os.path.exists(path), str(files))
    check("another seed: another image", image != reference and image.startswith(b"\x89PNG"))

    blocked = os.path.join(scratch, "not-a-directory")
    with open(blocked, "w") as f:
        f.write("a file where the cache's parent should be\n")
    image, err, _ = render(skyd, scratch, "unwritable", os.path.join(blocked, "skyd"))
    check("unwritable: a warning names the directory",
          f"cloud noise cache: cannot make {blocked}/skyd" in err, err[-400:])
    check("unwritable: the image is the same", image == reference)
    return summary(started)


if __name__ == "__main__":
    sys.exit(main())
