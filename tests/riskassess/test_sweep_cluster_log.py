"""riskassess.sweep.cluster_log: the Dask cluster's messages go to a file, not across the progress bar."""
import logging
import sys

from riskassess.sweep.cluster_log import StderrToFile, distributed_logging_to


def test_distributed_warnings_go_to_the_file_errors_still_to_the_terminal(tmp_path, capfd):
    log = tmp_path / "products" / "dask.log"
    with distributed_logging_to(log):
        logging.getLogger("distributed.worker.memory").warning("Unmanaged memory use is high")
        logging.getLogger("distributed.scheduler").error("a real scheduler error")
    text = log.read_text()
    assert "Unmanaged memory use is high" in text and "a real scheduler error" in text
    err = capfd.readouterr().err
    assert "Unmanaged memory" not in err
    logging.getLogger("distributed.worker.memory").warning("after the sweep")   # handlers restored
    assert "after the sweep" not in log.read_text()


def _noisy():
    print("worker noise on stderr", file=sys.stderr, flush=True)
    logging.getLogger("distributed.worker").error("worker log line")
    return 1


def test_worker_stderr_goes_to_the_file(tmp_path, capfd):
    from dask.distributed import Client, LocalCluster

    log = tmp_path / "dask.log"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        client.register_plugin(StderrToFile(log))
        assert list(client.run(_noisy).values()) == [1]
    text = log.read_text()
    assert "worker noise on stderr" in text and "worker log line" in text
    assert "worker noise" not in capfd.readouterr().err
