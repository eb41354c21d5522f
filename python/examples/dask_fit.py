#!/usr/bin/python3
"""Fit a folder of frame files (points CSVs) on a Dask distributed cluster with the camproj
Python module: `camproj fit FOLDER -o OUT` with the fits run by Dask's workers.

    dask_fit.py FOLDER -o OUT --image-size WxH [--workers 2 | --scheduler tcp://host:8786]
                [--files-per-task K] [--json]

Writes OUT/<name>.json for every FOLDER/<name>.csv the fitter accepts, the same camera files
`camproj fit FOLDER -o OUT` writes (fit times aside), and prints the CLI's batch table: one
`file<TAB>status<TAB>detail` line per input (status ok | refused | bad input), then the totals.
Exit code as the CLI's: the worst of the inputs' (0 ok, 2 bad input, 3 refused).

Without --scheduler it starts a LocalCluster of --workers processes with one thread each (a fit
is single-threaded and releases the GIL). With --scheduler it connects to a running cluster:
start `dask scheduler` on one host and `dask worker tcp://HOST:8786 --nthreads 1` on each
machine (every worker needs the camproj module on its PYTHONPATH); nothing else changes. The
driver reads every file and sends its text, and the workers send back the camera file text, so
the workers need no shared file system. --files-per-task groups files into one task each (fewer,
larger tasks: less scheduling per fit; see docs/scale-out.md for the measurements).
"""
import argparse
import os
import sys
import time


def fit_texts(items, width, height):
    """Runs on a worker: [(name, csv text)] -> [(name, status, detail, camera file text)]."""
    import camproj  # imported in the worker process

    results = []
    for name, text in items:
        try:
            points, pixels, ids = camproj.points_from_csv(text, name)
            camera = camproj.fit(points, pixels, (width, height), ids=ids)
            detail = f"{camera.report.model}, rms {camera.report.rms_px:.3f} px, {len(ids)} points"
            results.append((name, "ok", detail, camera.to_json()))
        except camproj.SceneError as error:
            results.append((name, "refused", str(error), None))
        except (ValueError, MemoryError) as error:
            results.append((name, "bad input", str(error), None))
    return results


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="folder of *.csv correspondence files")
    parser.add_argument("-o", "--output", required=True, help="folder for the camera files")
    parser.add_argument("--image-size", required=True, help="WIDTHxHEIGHT in pixels")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    parser.add_argument("--files-per-task", type=int, default=1)
    args = parser.parse_args(argv)
    width, height = (int(v) for v in args.image_size.split("x"))

    import camproj
    from dask.distributed import Client, LocalCluster, as_completed

    names = sorted(n for n in os.listdir(args.folder) if n.endswith(".csv"))
    if not names:
        sys.exit(f"dask_fit: {args.folder}: a folder without *.csv files")
    os.makedirs(args.output, exist_ok=True)
    items = []
    for name in names:
        with open(os.path.join(args.folder, name)) as f:
            items.append((os.path.join(args.folder, name), f.read()))
    batches = [items[i:i + args.files_per_task] for i in range(0, len(items), args.files_per_task)]

    if args.scheduler:
        cluster, client = None, Client(args.scheduler)
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        client.wait_for_workers(1)
        workers = len(client.scheduler_info()["workers"])
        begin = time.perf_counter()
        futures = client.map(fit_texts, batches, width=width, height=height, pure=False)
        # Written as they arrive, as the CLI writes each file when its fit is done.
        results = []
        for future in as_completed(futures):
            for path, status, detail, camera_text in future.result():
                if camera_text is not None:
                    stem = os.path.splitext(os.path.basename(path))[0]
                    # As the CLI writes them: atomically, flushed to disk.
                    camproj.write_file_atomically(os.path.join(args.output, stem + ".json"), camera_text)
                results.append((path, status, detail))
        seconds = time.perf_counter() - begin
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

    results.sort()
    exit_code = max({"ok": 0, "bad input": 2, "refused": 3}[status] for _, status, _ in results)
    print("file\tstatus\tdetail")
    for path, status, detail in results:
        print(f"{path}\t{status}\t{detail}")
    ok = sum(status == "ok" for _, status, _ in results)
    print(f"{ok} of {len(results)} fitted in {seconds:.3f} s on {workers} Dask workers "
          f"({len(results) / seconds:.1f} fits/s); cameras in {args.output}")
    return exit_code


if __name__ == "__main__":
    sys.exit(main())
