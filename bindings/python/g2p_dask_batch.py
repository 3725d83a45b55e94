"""`g2p batch --scheduler ADDRESS`: the batch through g2p.batch on a Dask cluster.

The g2p command line becomes this program (python3 g2p_dask_batch.py ARGS_JSON) and
reports as `g2p batch` does: the same progress lines, summary and exit codes.
ARGS_JSON holds the batch's arguments, its options as an options file's text included.
"""
import json
import signal
import sys


def main(argv):
    a = json.loads(argv[1])
    try:
        import g2p
        from distributed import Client
    except ImportError as e:
        sys.stderr.write("g2p batch: --scheduler needs the g2p Python module (PYTHONPATH) and "
                         "python3-distributed: %s\n" % e)
        return 2

    def on_term(signum, frame):
        raise SystemExit(143)

    signal.signal(signal.SIGTERM, on_term)
    try:
        client = Client(a["scheduler"], timeout=a["connect_timeout"])
    except Exception as e:  # the address is shown without its credentials
        sys.stderr.write("g2p batch: error: cannot reach the Dask scheduler at %s (%s)\n"
                         % (a["shown"], type(e).__name__))
        return 1

    def progress(p):
        if p["last"] and not a["quiet"]:
            eta = "-" if p["eta_s"] < 0 else "%.0fs" % p["eta_s"]
            sys.stderr.write("g2p batch: [%d/%d, %d failed, ETA %s] %s\n"
                             % (p["done"], p["total"], p["failed"], eta, p["last"]))

    stopped = "g2p batch: stopped (%s); finished assets and the index are kept, a rerun goes on from here\n"
    try:
        options, materials = g2p.parse_options_file(a["options"])
        rows = g2p.batch(a["inputs"] or None, a["output"], manifest=a["manifest"] or None, timeout=a["timeout"],
                         memory_limit=a["memory_limit"], options=options, materials=materials,
                         retry_failed=a["retry_failed"], progress=progress, client=client)
    except KeyboardInterrupt:
        sys.stderr.write(stopped % "SIGINT")
        return 130
    except SystemExit as e:
        if e.code == 143:
            sys.stderr.write(stopped % "SIGTERM")
        raise
    except g2p.Error as e:
        sys.stderr.write("g2p batch: error: %s\n" % e)
        return 2 if isinstance(e, g2p.InvalidArgumentError) else 1
    finally:
        client.close()
    ok = sum(r["status"] == "ok" for r in rows)
    failed = [r for r in rows if r["status"] == "failed"]
    for r in failed:
        origin = "" if r["origin"] == r["input"] else " (%s)" % r["origin"]
        sys.stderr.write("g2p batch: failed: %s%s: %s\n" % (r["name"], origin, r["error"]))
    print("%d assets: %d ok, %d failed on the Dask cluster -> %s/index.csv" % (len(rows), ok, len(failed), a["output"]))
    return 1 if ok == 0 or (a["fail_on_error"] and failed) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
