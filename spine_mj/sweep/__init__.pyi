"""The public names of :mod:`spine_mj.sweep`, for type checkers and the docs; ``__init__.py``
loads each from its home on first use (``lazy_loader.attach_stub`` reads this file)."""

from .analyses.engine import ENGINE_PARAMS as ENGINE_PARAMS
from .analyses.quasistatic import QUASISTATIC_PARAMS as QUASISTATIC_PARAMS
from .case_runs import run_case as run_case
from .cases import Case as Case
from .cases import expand_cases as expand_cases
from .config import StartsSpec as StartsSpec
from .config import SurfaceSpec as SurfaceSpec
from .config import SweepConfig as SweepConfig
from .config import load_config as load_config
from .config import parse_config as parse_config
from .executors import DEFAULT_WORKER_WAIT_S as DEFAULT_WORKER_WAIT_S
from .executors import SchedulerUnavailable as SchedulerUnavailable
from .pool import WorkersCannotStart as WorkersCannotStart
from .registry import ANALYSES as ANALYSES
from .registry import REQUIRED as REQUIRED
from .registry import STATUSES as STATUSES
from .registry import Analysis as Analysis
from .registry import AnalysisResult as AnalysisResult
from .registry import ParamSpec as ParamSpec
from .registry import register_analysis as register_analysis
from .report import write_report as write_report
from .session import Progress as Progress
from .session import SweepSummary as SweepSummary
from .session import run_sweep as run_sweep
from .session import run_sweeps as run_sweeps
from .store import StoreStatus as StoreStatus
from .store import consolidate as consolidate
from .store import load_runs as load_runs
from .store import load_trajectories as load_trajectories
from .store import store_status as store_status
