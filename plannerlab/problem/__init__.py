"""Problems: loading and validating problem files (see ``docs/problem-format.md``)."""

from plannerlab.problem.catalog import list_problems, load_problem, resolve_problem_path
from plannerlab.problem.load import Budget, Problem

__all__ = ["Budget", "Problem", "list_problems", "load_problem", "resolve_problem_path"]
