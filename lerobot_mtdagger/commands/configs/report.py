"""Options of ``lerobot-mtdagger report``: which runs or tables, and where the figures go."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lerobot_mtdagger.analysis.compare import runs_not_started
from lerobot_mtdagger.analysis.saved_records import saved_records_runs
from lerobot_mtdagger.datasets.experiment_files import CONFIG_FILE
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.paths import check_input_path, check_output_dir, check_output_file


@dataclass
class ReportConfig:
    """Options of ``lerobot-mtdagger report``: success against expert demos, method by method.

    Attributes:
        experiments: Experiment directories (several seeds of several methods).
        compare_dir: A ``compare`` folder (its runs are the experiments); instead of ``experiments``.
        output_dir: Folder for the figures and ``report.md`` (default ``<compare_dir>/report``; with
            ``experiments`` only, no figures unless given).
        output: Optional markdown file for the table.
        levels: Success levels of the "demos to reach" and "time to reach" figures.
        variants: More runs reported under a method name of their own, by name: a ``compare`` folder
            or one experiment each, e.g. ``--variants='{bc-balanced: outputs/bc-balanced}'`` for BC
            trained with balanced sampling beside the ``bc`` of ``compare_dir``. A BC variant is a
            baseline like ``bc``.
        results: Saved results tables instead of run folders: each a ``results.json`` that ``report
            --output_dir`` or ``compare`` wrote, or its folder. Draws the figures and ``report.md`` from
            the tables alone, e.g. after the run folders are gone, with other ``--levels``, or joining
            seeds run on other machines (each point in one table only; the methods' configs must
            agree). Default ``output_dir`` for one table: its folder.
        records: Runs' saved records (``scripts/save_run_records.sh``: config, round and training
            records, no frames or weights), each a run's records folder, a folder of them, or a
            study's ``runs-records.tar.gz`` (or a folder holding them: ``analysis.saved_records``), reported
            beside ``experiments`` and ``compare_dir`` as their runs are: a study whose ``outputs/`` was
            lost keeps its finished runs. Their frames per task are known only on average.
        unverified: Report runs that fail verification (a changed record or file, a missing ledger) as
            they are, with a warning, and say so in ``report.md``; by default each is left out, named
            with the reason, and the report goes on with the rest.
    """

    experiments: list[Path] = field(default_factory=list)
    compare_dir: Path | None = None
    results: list[Path] = field(default_factory=list)
    output_dir: Path | None = None
    output: Path | None = None
    levels: list[float] = field(default_factory=lambda: [0.5, 0.6, 0.7, 0.8])
    variants: dict[str, Path] = field(default_factory=dict)
    records: list[Path] = field(default_factory=list)
    unverified: bool = False

    def __post_init__(self) -> None:
        if self.results:
            self._check_results_options()
            return
        if not self.experiments and self.compare_dir is None and not self.records:
            raise ValueError(
                "--experiments, --compare_dir, --records or --results is required, e.g. "
                "--experiments='[outputs/need-s0,outputs/bc-s0]', --compare_dir=outputs/compare, "
                "--records='[experiments/pixels-eval/records]' or "
                "--results='[experiments/mt10-state-eval/report]'."
            )
        for folder in self.records:
            saved_records_runs(Path(folder))  # refuses a folder without records now, not mid-report
        if self.compare_dir is not None and not (self.compare_dir / "runs").is_dir():
            raise ValueError(f"{self.compare_dir} is not a compare folder (no runs/ in it).")
        if self.compare_dir is not None and self.output_dir is None:
            self.output_dir = self.compare_dir / "report"
        self._check_outputs()
        for name, folder in self.variants.items():
            if not (Path(folder) / "runs").is_dir() and not (Path(folder) / CONFIG_FILE).is_file():
                raise ValueError(
                    f"--variants: {folder} (for {name!r}) is neither a compare folder (runs/) nor an "
                    "experiment: give the folder compare or run wrote."
                )

    def _check_results_options(self) -> None:
        """``--results`` goes without run folders; several tables need an ``--output_dir``."""
        if self.experiments or self.compare_dir is not None or self.variants or self.records:
            raise ValueError(
                "--results draws saved tables: give it alone, without --experiments, --compare_dir, "
                "--variants or --records (their runs are tabulated afresh instead)."
            )
        if self.output_dir is None and len(self.results) > 1:
            raise ValueError(
                f"--results joins {len(self.results)} tables: give --output_dir for the joined report "
                "(it is never written into one of the tables' folders unasked)."
            )
        if self.output_dir is None:
            table = Path(self.results[0])
            self.output_dir = table if table.is_dir() else table.parent
        self._check_outputs()

    def _check_outputs(self) -> None:
        """Refuses an output folder or file that cannot be written, before any table is made."""
        if self.output_dir is not None:
            check_output_dir(self.output_dir, "--output_dir")
        if self.output is not None:
            check_output_file(self.output, "--output")

    def check_paths(self) -> None:
        """Refuses an ``--experiments`` folder or a ``--results`` table that is not there.

        ``--compare_dir``, ``--variants`` and ``--records`` are checked as the options are parsed.

        Raises:
            UserError: Naming the option, the path and the fix.
        """
        for folder in self.experiments:
            check_input_path(folder, "--experiments", "experiment folders (the --output_dir of runs)")
        for table in self.results:
            if not Path(table).exists():
                raise UserError(
                    f"{table} does not exist: pass the results.json that `report --output_dir` or `compare` "
                    "wrote, or the folder that holds it."
                )

    @property
    def experiment_dirs(self) -> list[Path]:
        """The experiments to report on (the variants' last)."""
        mine = list(self.experiments)
        if self.compare_dir is not None:
            mine += _compare_runs(self.compare_dir)
        for folder in self.records:
            mine += saved_records_runs(Path(folder))
        return mine + list(self.labels)

    @property
    def labels(self) -> dict[Path, str]:
        """The method name of each variant's experiments."""
        return {
            run: name
            for name, folder in self.variants.items()
            for run in (_compare_runs(Path(folder)) if (Path(folder) / "runs").is_dir() else [Path(folder)])
        }

    @property
    def runs_not_started(self) -> list[str]:
        """The runs the compare folders plan (``compare.json``) that have no folder yet."""
        folders = [self.compare_dir] if self.compare_dir is not None else []
        folders += [Path(folder) for folder in self.variants.values() if (Path(folder) / "runs").is_dir()]
        return [f"{name}: not started" for folder in folders for name in runs_not_started(folder)]


def _compare_runs(compare_dir: Path) -> list[Path]:
    """The run folders of a ``compare`` folder."""
    return sorted(p for p in (compare_dir / "runs").iterdir() if p.is_dir())
