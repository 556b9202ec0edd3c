"""Sweep the L2 size with `dualsplit.simulate` and plot frame time per structure.

    pip install ./python matplotlib
    python python/examples/l2_sweep.py [SCENE] [-o l2_sweep.png]

Each point is one simulated frame (the `fast` thread model, 128x128 path tracing by
default); the configuration is the paper's (lin2020) with `l2.size_bytes` changed.
"""

import argparse

import dualsplit


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?", default="builtin:hairball?triangles=100000")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--model", default="fast", choices=["fast", "rv32"])
    ap.add_argument("--accel", default="bvh2,bvh4,dst")
    ap.add_argument("-o", "--output", default="l2_sweep.png")
    args = ap.parse_args()

    scene = dualsplit.load_scene(args.scene)
    sizes_kib = [256, 512, 1024, 2048, 4096, 8192]
    accels = args.accel.split(",")
    frame_ms = {a: [] for a in accels}
    for kib in sizes_kib:
        doc = dualsplit.simulate(
            scene,
            accel=accels,
            res=args.res,
            model=args.model,
            config={"l2.size_bytes": kib * 1024},
        )
        for r in doc["results"]:
            frame_ms[r["accel"]].append(r["frame_ms"])
        print(f"L2 {kib:5d} KiB: " + ", ".join(f"{a} {frame_ms[a][-1]:.3f} ms" for a in accels))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for a in accels:
        ax.plot(sizes_kib, frame_ms[a], marker="o", label=a)
    ax.set_xscale("log", base=2)
    ax.set_xlabel("L2 size (KiB)")
    ax.set_ylabel("frame time (ms)")
    ax.set_title(f"{scene.name}, {args.res}x{args.res} path, {args.model} model")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
