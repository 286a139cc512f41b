"""Counts the rooms (source files) a `set` walks through, from the trace of scenario.py.
Units, in order: (a) the lws callback that receives the set and queues it; (b) the render
thread's ticks from the one that runs the set through the one that renders the first frame
after it; (c) the encoder job of that frame; (d) the lws callbacks from the job's end through
the one that writes that frame's binary message. In each unit every call into a function of
another file than its caller's is an entry into that file (the unit's first call too); a
return to a room already left is every entry after a file's first.
Usage: analyze.py SKYD TRACE [--list] [--all]
By default a call from one function to another counts once however often the walk makes it
(a loop over the schema's fields is one entry); --all counts every call.
Inline functions of headers are not rooms."""
import collections, os, struct, subprocess, sys

skyd, trace = sys.argv[1], sys.argv[2]
raw = open(trace, "rb").read()
evs = [struct.unpack_from("<QQIi", raw, i * 24) for i in range(len(raw) // 24)]
addrs = sorted({e[1] for e in evs})
out = subprocess.run(["addr2line", "-f", "-e", skyd] + [hex(a) for a in addrs],
                     capture_output=True, text=True).stdout.split("\n")
names, files = {}, {}
for i, a in enumerate(addrs):
    names[a] = out[2 * i]
    path = out[2 * i + 1].split(":")[0]
    parts = path.split("/")
    files[a] = "/".join(parts[-2:]) if parts else path
    if "/render/" in path:
        files[a] = "render/" + parts[-1]
by_tid = collections.defaultdict(list)
for e in evs:
    by_tid[e[2]].append(e)
for t in by_tid:
    by_tid[t].sort(key=lambda e: e[0])

def tid_calling(fn):
    for t, es in by_tid.items():
        if any(names[e[1]] == fn for e in es):
            return t
    raise SystemExit(f"no thread calls {fn}")

def units(es, top_names=None, parent=None):
    """Splits a thread's events into units: the calls made at the outermost depth seen, or
    (parent) the calls whose caller is `parent`."""
    res, stack, cur = [], [], None
    for e in es:
        if e[3] == 1:
            caller = names[stack[-1][1]] if stack else None
            start = (not stack) or caller == parent
            if start:
                cur = []
                res.append(cur)
            stack.append(e)
        else:
            if stack:
                stack.pop()
        if cur is not None:
            cur.append(e)
    return res

def has(unit, fn):
    return any(names[e[1]] == fn and e[3] == 1 for e in unit)

lws = tid_calling("render_loop_submit_message")
rt = tid_calling("handle_set")
lws_units = units(by_tid[lws])
a = [u for u in lws_units if has(u, "render_loop_submit_message")][-1]
# render ticks: split thread_main's children at frame_scheduler_last_stats
children = units(by_tid[rt], parent="thread_main")
ticks, cur = [], None
for u in children:
    if names[u[0][1]] == "frame_scheduler_last_stats" or cur is None:
        if names[u[0][1]] == "frame_scheduler_last_stats":
            cur = []
            ticks.append(cur)
    if cur is not None:
        cur.extend(u)
first = next(i for i, t in enumerate(ticks) if has(t, "handle_set"))
set_time = next(e[0] for e in ticks[first] if names[e[1]] == "handle_set")
last = next(i for i in range(first, len(ticks))
            if any(names[e[1]] == "encoder_pool_submit" and e[3] == 1 and e[0] > set_time
                   for e in ticks[i]))
b = [e for t in ticks[first:last + 1] for e in t]
submit_t = next(e[0] for e in ticks[last] if names[e[1]] == "encoder_pool_submit" and e[0] > set_time)
jobs = [u for t, es in by_tid.items() if t not in (lws, rt)
        for u in units(es, parent="worker") if names[u[0][1]] == "run_job" and u[0][0] > submit_t]
c = min(jobs, key=lambda u: u[0][0])
job_end = c[-1][0]
d_all = [u for u in lws_units if u[0][0] > job_end]
d = []
for u in d_all:
    d.append(u)
    if has(u, "lws_write_binary") or sum(has(x, "on_writeable") for x in d) >= 2:
        break
walk = [("lws receive", a)] + [("render ticks", b)] + [("encoder", c)] + \
       [("lws write", u) for u in d]
entries = collections.Counter()
order = []
seen = set()
dedup = "--all" not in sys.argv
for label, u in walk:
    stack = []
    for e in u:
        if e[3] == 1:
            f = files[e[1]]
            caller = files[stack[-1][1]] if stack else None
            edge = (names[stack[-1][1]] if stack else label, names[e[1]])
            if f != caller and not f.endswith(".h") and not (dedup and edge in seen):
                entries[f] += 1
                order.append((label, f, names[e[1]], caller))
            seen.add(edge)
            stack.append(e)
        elif stack:
            stack.pop()
total = sum(entries.values())
print(f"ticks {last - first + 1}, lws write units {len(d)}")
print(f"rooms {len(entries)}, entries {total}, returns {total - len(entries)}")
for f, n in entries.most_common():
    print(f"  {n:3d} {f}")
if "--list" in sys.argv:
    for label, f, fn, caller in order:
        print(f"{label:14s} {caller or '-':28s} -> {f:28s} {fn}")

# The walk as a sequence of rooms, calls and returns alike: a room is entered each time the
# walk comes into it, from a callee's return too; repeated calls (same caller and callee) are
# skipped with everything under them.
seq = []
seen = set()
for label, u in walk:
    stack, skip = [], 0
    for e in u:
        if e[3] == 1:
            edge = (names[stack[-1][1]] if stack else label, names[e[1]])
            if skip or (dedup and edge in seen):
                skip += 1
                continue
            seen.add(edge)
            stack.append(e)
            f = files[e[1]]
            if not f.endswith(".h"):
                seq.append(f)
        else:
            if skip:
                skip -= 1
                continue
            if stack:
                stack.pop()
                if stack and not files[stack[-1][1]].endswith(".h"):
                    seq.append(files[stack[-1][1]])
runs = [f for i, f in enumerate(seq) if i == 0 or seq[i - 1] != f]
visits = collections.Counter(runs)
print(f"walk (calls and returns): rooms {len(visits)}, visits {len(runs)}, "
      f"returns {len(runs) - len(visits)}")
for f, n in visits.most_common():
    print(f"  {n:3d} {f}")
if "--walk" in sys.argv:
    print(" -> ".join(runs))
