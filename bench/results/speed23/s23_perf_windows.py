"""perf report per window of a bench_capture_cost run: own samples per function, numba's names shortened."""
import re
import subprocess
import sys

label, windows, top = sys.argv[1], sys.argv[2].split(","), int(sys.argv[3]) if len(sys.argv) > 3 else 22
text = open(f"/tmp/speed23/cap_{label}.txt").read()
marks = {m.group(1): m.group(2) for m in re.finditer(r"perf mark: window (\S+) s starts at CLOCK_MONOTONIC (\S+)", text)}
order = list(marks)
end = re.search(r"perf mark: end at CLOCK_MONOTONIC (\S+)", text).group(1)
for w in windows:
    k = order.index(w)
    stop = marks[order[k + 1]] if k + 1 < len(order) else end
    out = subprocess.run(["perf", "report", "-i", f"/tmp/speed23/perf_{label}.data", "--no-children", "--sort", "sym",
                          "--time", f"{marks[w]},{stop}"], capture_output=True, text=True).stdout
    print(f"== {label} window {w} s")
    n = 0
    for line in out.splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        line = line.replace("[.] ", "").replace("[k] ", "")
        m = re.match(r"\s*([\d.]+%)\s+_ZN9multibody\d+(\w+?)\d+(\w+?)B\d", line)
        if m:
            pct = m.group(1)
            name = re.sub(r"^_ZN9multibody", "", line.split()[-1])
            parts = re.findall(r"(\d+)([A-Za-z_]\w*)", name)
            mod, fn = [], None
            rest = name
            names = []
            while rest and rest[0].isdigit():
                num = re.match(r"\d+", rest).group(0)
                ln = int(num)
                names.append(rest[len(num):len(num) + ln])
                rest = rest[len(num) + ln:]
            line = f"{pct:>8}  multibody.{'.'.join(names)}"
        print(line[:110])
        n += 1
        if n >= top:
            break
