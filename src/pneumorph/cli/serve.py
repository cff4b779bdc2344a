"""``pneumorph serve``: the designer's bench, a local web page over the certified search."""

from __future__ import annotations

import errno
import ipaddress
import socket

import click

from pneumorph.cli.options import params as P


def _check_port(host: str, port: int) -> None:
    """Refuse a host that does not resolve or a port that is taken, before anything starts."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as exc:
        raise click.BadParameter(f"cannot resolve {host!r} ({exc.strerror})", param_hint="--host") from None
    family, _, _, _, address = infos[0]
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError as exc:
            why = "is in use" if exc.errno == errno.EADDRINUSE else f"cannot be used ({exc.strerror})"
            raise click.BadParameter(f"{host}:{port} {why}; choose another with --port", param_hint="--port") \
                from None


def _is_local(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


def allowed_hosts(host: str, extra: tuple[str, ...]) -> tuple[str, ...]:
    """The ``Host`` names the bench serves: the address it listens on, this machine's loopback names when it
    listens there, its own names when it listens on every address, and ``--allow-host``.

    Examples
    --------
    >>> allowed_hosts("127.0.0.1", ())
    ('127.0.0.1', 'localhost', '::1')
    >>> allowed_hosts("10.0.0.5", ("bench.lab.example",))
    ('10.0.0.5', 'bench.lab.example')
    """
    names = [host]
    if _is_local(host):
        names += ["127.0.0.1", "localhost", "::1"]
    elif host in ("0.0.0.0", "::"):
        names += ["127.0.0.1", "localhost", "::1", socket.gethostname(), socket.getfqdn()]
    names += list(extra)
    return tuple(dict.fromkeys(n.lower() for n in names if n))


@click.command("serve")
@click.option("--host", default="127.0.0.1", show_default=True, type=P.Text(),
              help="Address to listen on (this machine only by default).")
@click.option("--port", default=8000, show_default=True, type=P.Count(1, 65535), help="Port to listen on.")
@click.option("--open", "open_browser", is_flag=True, help="Open the page in the default browser.")
@click.option("--state", metavar="DIR", type=P.OutputDir(),
              help="Jobs and shapes of the bench (default: bench/ beside the evaluation cache).")
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="Evaluation cache (SQLite) shared with design runs; default ~/.cache/pneumorph/evaluations.sqlite.")
@click.option("--workers", default=1, show_default=True, type=P.WORKERS,
              help="FE worker processes of a background job.")
@click.option("--allow-host", "allow_host", multiple=True, type=P.Text(max_length=253), metavar="NAME",
              help="Another host name the page may be reached by (repeatable); requests naming any other host are "
                   "refused (DNS rebinding).")
@click.option("--jobs-per-session", default=2, show_default=True, type=P.Count(1, 100),
              help="Background jobs one browser session may have queued or running at once.")
@click.option("--max-jobs", default=8, show_default=True, type=P.Count(1, 1000),
              help="Background jobs all sessions together may have queued or running.")
@click.option("--job-days", default=7.0, show_default=True, type=P.Real(0.0, 3650.0, low_open=True, unit="days"),
              help="Finished jobs and their files are deleted this long after they started.")
@click.option("--state-quota", default=2000.0, show_default=True, type=P.Real(1.0, 1e7, unit="MB"),
              help="Disk space the jobs may take in the state folder (MB): past it the oldest finished jobs are "
                   "deleted, and new jobs are refused while running ones fill it.")
@click.option("--model-file", type=P.InputFile(),
              help="A model's [model] table (an identified model, identified.toml from pneumorph identify) under every "
                   "answer and job: its unit is the bench's built-in unit, its material scales apply to every unit "
                   "(its chain table: `pneumorph design --model-file FILE` builds it on the same cache).")
def serve(host: str, port: int, open_browser: bool, state: str | None, cache: str | None, workers: int,
          allow_host: tuple[str, ...], jobs_per_session: int, max_jobs: int, job_days: float,
          state_quota: float, model_file: str | None = None) -> None:
    """Open the designer's bench: type or draw a target, see the certified design at once.

    A local web page: the target as a preset, an expression, a tip goal or a curve drawn
    with the mouse; the chain model's certified optimum, its pressure, error and
    certificate, the best designs, the profile at every pressure and the 3D shape; FE
    verification and export (STL, mould, CalculiX deck) in the background, each job in a
    process of its own, with downloads. Requests of 1 MB at most (unit files 64 kB); only
    this page may start work (same origin, JSON); sessions are signed cookies. Stop it with
    Ctrl-C (or SIGTERM): a running job is stopped and marked interrupted.
    """
    try:
        import itsdangerous  # noqa: F401
        import uvicorn

        from pneumorph.bench.app import create_app
    except ImportError as exc:
        raise click.UsageError(f"the bench needs the web extra ({exc.name} is missing): pip install "
                               '"pneumorph[web]" (in a checkout of the repository: pip install -e ".[web]")') from None
    settings = None
    if model_file is not None:
        from pneumorph.models.factory import make_model, read_model_file

        with P.blame("--model-file"):
            settings = {k: v for k, v in read_model_file(model_file).items() if k != "fidelity"}
            make_model(1, settings)  # its settings checked before the server starts
    _check_port(host, port)
    from pneumorph.bench.app import default_state_dir
    from pneumorph.bench.jobs import JobLimits
    from pneumorph.io.files import check_writable_dir

    check_writable_dir(state if state is not None else default_state_dir(), "--state")
    limits = JobLimits(per_session=jobs_per_session, queued=max_jobs, expiry_days=job_days, quota_mb=state_quota)
    app = create_app(state_dir=state, cache=cache, workers=workers, allowed_hosts=allowed_hosts(host, allow_host),
                     limits=limits, model_settings=settings)
    url = f"http://{'[' + host + ']' if ':' in host else host}:{port}/"
    click.echo(f"pneumorph bench at {url} (Ctrl-C stops it)" + (f", serving the model of {model_file}"
                                                                   if model_file is not None else ""))
    if not _is_local(host):
        click.echo(f"warning: listening on {host}: anyone who can reach this machine can use the bench", err=True)
    if open_browser:
        import threading
        import webbrowser

        threading.Timer(1.0, webbrowser.open, args=(url,)).start()
    # open connections get 3 s after Ctrl-C or SIGTERM; then the jobs are stopped (the app's lifespan)
    uvicorn.run(app, host=host, port=port, log_level="warning", timeout_graceful_shutdown=3)
