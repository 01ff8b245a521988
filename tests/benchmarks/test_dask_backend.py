"""The Dask backend (benchmarks/dask_backend.py) on a local cluster started in the test."""

import os

import pytest

from sarcover.benchmarks.cli import main
from sarcover.benchmarks.harness import run_suite
from sarcover.benchmarks.suite import load_suite

from bench_suites import SMALL, rows_of, write_suite


def test_dask_path_gives_the_same_results_as_local(tmp_path):
    """Dask on loopback stores the same rows as the local pool; a job past its deadline is time_limit."""
    distributed = pytest.importorskip("dask.distributed")
    suite = load_suite(str(write_suite(tmp_path, SMALL.replace('"greedy", "cpsat"', '"greedy"'))))
    run_suite(suite, tmp_path / "local", workers=2, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None, host="127.0.0.1", protocol="tcp") as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        assert main(["bench", str(suite.path), "-o", str(tmp_path / "dask"), "--quiet",
                     "--scheduler", cluster.scheduler_address]) == 0
        napping = write_suite(tmp_path, 'methods = ["bench_methods:nap"]\ntime_limit = 0.2\ngrace = 0.2\n'
                                        '[[instances]]\nM = 2\nK = 2\nN = 1', "nap.toml")
        assert main(["bench", str(napping), "-o", str(tmp_path / "nap"), "--quiet",
                     "--scheduler", cluster.scheduler_address]) == 0
    [nap] = rows_of(tmp_path / "nap")
    assert nap["status"] == "time_limit" and "killed after" in nap["reason"]

    def essence(rows):
        return sorted((r["key"], r["status"], r["objective"], r["routes"], r["valid"]) for r in rows)

    local, dask = rows_of(tmp_path / "local"), rows_of(tmp_path / "dask")
    assert len(local) == len(suite.jobs) == 5
    assert essence(local) == essence(dask)
    assert all(r["workers"] is None for r in dask)


def test_an_overrunning_job_is_killed_and_the_next_job_runs_alone(tmp_path, monkeypatch):
    """On Dask, an overrun is killed with its child, a dead child is an error, and the next job has its core alone."""
    distributed = pytest.importorskip("dask.distributed")
    marks = tmp_path / "marks"
    marks.mkdir()
    monkeypatch.setenv("SARCOVER_TEST_MARKS", str(marks))
    suite = write_suite(tmp_path, 'methods = ["bench_methods:spin", "bench_methods:die", "bench_methods:measured"]\n'
                                  'time_limit = 0.3\n'
                                  'grace = 0.3\n[method."bench_methods:measured"]\ntime_limit = 60\n'
                                  '[[instances]]\nM = 2\nK = 2\nN = 1\ne_max = 20000\n')
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None,
                                  host="127.0.0.1", protocol="tcp") as cluster:
        summary = run_suite(load_suite(str(suite)), tmp_path / "res", scheduler=cluster.scheduler_address,
                            progress=False)
    assert summary["counts"] == {"time_limit": 1, "error": 1, "optimal": 1}
    rows = {r["method"]: r for r in rows_of(tmp_path / "res")}
    spin, measured = rows["bench_methods:spin"], rows["bench_methods:measured"]
    assert spin["status"] == "time_limit" and "killed after" in spin["reason"]
    assert rows["bench_methods:die"]["reason"] == "job process exited with code 3"
    [mark] = marks.iterdir()
    spin_pid = int(mark.name.split(".")[1])
    with pytest.raises(ProcessLookupError):
        os.kill(spin_pid, 0)
    assert measured["valid"] and measured["pid"] not in (spin_pid, os.getpid())
    assert measured["info"]["other_threads_cpu_s"] < 0.1, measured["info"]


def _self_signed(folder):
    """(certificate, key) PEM files of a self-signed certificate for 127.0.0.1, which also serves
    as its own CA: with the ``cryptography`` package if installed, else the ``openssl`` command."""
    import shutil
    import subprocess

    cert, key = folder / "cert.pem", folder / "key.pem"
    try:
        import datetime
        import ipaddress

        from cryptography import x509
        from cryptography.hazmat.primitives import hashes, serialization
        from cryptography.hazmat.primitives.asymmetric import rsa
        from cryptography.x509.oid import NameOID
    except ImportError:
        if shutil.which("openssl") is None:
            pytest.skip("neither the cryptography package nor openssl is installed")
        subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", str(key), "-out",
                        str(cert), "-days", "1", "-subj", "/CN=localhost",
                        "-addext", "subjectAltName=IP:127.0.0.1,DNS:localhost"], check=True, capture_output=True)
        return cert, key
    private = rsa.generate_private_key(public_exponent=65537, key_size=2048)
    name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "localhost")])
    now = datetime.datetime.now(datetime.timezone.utc)
    certificate = (x509.CertificateBuilder().subject_name(name).issuer_name(name).public_key(private.public_key())
                   .serial_number(x509.random_serial_number()).not_valid_before(now)
                   .not_valid_after(now + datetime.timedelta(days=1))
                   .add_extension(x509.SubjectAlternativeName([x509.IPAddress(ipaddress.ip_address("127.0.0.1")),
                                                               x509.DNSName("localhost")]), critical=False)
                   .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
                   .sign(private, hashes.SHA256()))
    cert.write_bytes(certificate.public_bytes(serialization.Encoding.PEM))
    key.write_bytes(private.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.TraditionalOpenSSL,
                                          serialization.NoEncryption()))
    return cert, key


def test_a_suite_runs_on_a_tls_secured_cluster_and_is_refused_without_certificates(tmp_path, capsys):
    """A TLS-only cluster runs a suite given --tls-* certificates, and refuses one without (one line, exit 2)."""
    distributed = pytest.importorskip("dask.distributed")
    from distributed.security import Security

    cert, key = _self_signed(tmp_path)
    roles = {f"tls_{who}_{part}": str(path) for who in ("scheduler", "worker", "client")
             for part, path in (("cert", cert), ("key", key))}
    security = Security(tls_ca_file=str(cert), require_encryption=True, **roles)
    suite = write_suite(tmp_path, SMALL.replace('"greedy", "cpsat"', '"greedy"'))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None,
                                  host="127.0.0.1", protocol="tls", security=security) as cluster:
        address = cluster.scheduler_address
        assert address.startswith("tls://127.0.0.1:")
        assert main(["bench", str(suite), "-o", str(tmp_path / "tls"), "--quiet", "--scheduler", address,
                     "--tls-ca-file", str(cert), "--tls-cert", str(cert), "--tls-key", str(key)]) == 0
        capsys.readouterr()
        assert main(["bench", str(suite), "-o", str(tmp_path / "plain"), "--quiet", "--scheduler", address]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--tls-ca-file" in err
    assert not (tmp_path / "plain").exists()
    rows = rows_of(tmp_path / "tls")
    assert len(rows) == 5 and all(r["valid"] for r in rows)


def test_tls_flags_are_checked_before_anything_runs(tmp_path, capsys):
    """A TLS flag without --scheduler, without the CA, or naming a missing file: one line, exit 2."""
    suite = write_suite(tmp_path, SMALL.replace('"greedy", "cpsat"', '"greedy"'))
    cert = tmp_path / "c.pem"
    cert.write_text("x")
    for extra, needle in [(["--tls-cert", str(cert), "--tls-ca-file", str(cert)], "--scheduler"),
                          (["--scheduler", "tls://127.0.0.1:1", "--tls-cert", str(cert)], "--tls-ca-file is missing"),
                          (["--scheduler", "tls://127.0.0.1:1", "--tls-cert", str(cert), "--tls-ca-file",
                            str(tmp_path / "none.pem")], "no such file")]:
        assert main(["bench", str(suite), "-o", str(tmp_path / "r"), "--quiet", *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and needle in err, err
    assert not (tmp_path / "r").exists()
