"""OR-Tools and HiGHS (directly and through Pyomo) import and solve in one process."""

from __future__ import annotations

import highspy
import numpy as np
import pyomo.environ as pyo
from ortools.sat.python import cp_model
from pyomo.contrib.solver.common.factory import SolverFactory
from pyomo.contrib.solver.common.results import TerminationCondition


def test_ortools_and_highs_solve_in_one_process():
    """CP-SAT, a highspy LP and a Pyomo HiGHS MIP all reach their hand-checked optima in turn."""
    # CP-SAT: max x + 2y with x + y <= 3, y <= 2 -> x = 1, y = 2, objective 5
    cp = cp_model.CpModel()
    x = cp.new_int_var(0, 3, "x")
    y = cp.new_int_var(0, 2, "y")
    cp.add(x + y <= 3)
    cp.maximize(x + 2 * y)
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = 1
    assert solver.solve(cp) == cp_model.OPTIMAL and solver.objective_value == 5

    # highspy LP: min x + y with x + 2y >= 2, 3x + y >= 3 -> x = 0.8, y = 0.6, objective 1.4
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.addVars(2, np.zeros(2), np.full(2, highspy.kHighsInf))
    h.changeColsCost(2, np.array([0, 1], dtype=np.int32), np.array([1.0, 1.0]))
    h.addRow(2.0, highspy.kHighsInf, 2, np.array([0, 1], dtype=np.int32), np.array([1.0, 2.0]))
    h.addRow(3.0, highspy.kHighsInf, 2, np.array([0, 1], dtype=np.int32), np.array([3.0, 1.0]))
    h.run()
    assert h.getModelStatus() == highspy.HighsModelStatus.kOptimal
    assert abs(h.getInfo().objective_function_value - 1.4) < 1e-9

    # Pyomo + HiGHS MIP: knapsack, weights 3, 4, 5, values 4, 5, 6, capacity 8 -> items 1 and 3, value 10
    m = pyo.ConcreteModel()
    m.I = pyo.Set(initialize=[0, 1, 2])
    w, v = [3, 4, 5], [4, 5, 6]
    m.b = pyo.Var(m.I, domain=pyo.Binary)
    m.cap = pyo.Constraint(expr=sum(w[i] * m.b[i] for i in m.I) <= 8)
    m.obj = pyo.Objective(expr=sum(v[i] * m.b[i] for i in m.I), sense=pyo.maximize)
    res = SolverFactory("highs").solve(m, raise_exception_on_nonoptimal_result=False, load_solutions=False,
                                       solver_options={"mip_rel_gap": 0.0, "output_flag": False})
    assert res.termination_condition == TerminationCondition.convergenceCriteriaSatisfied
    res.solution_loader.load_vars()
    assert round(pyo.value(m.obj)) == 10 and [round(m.b[i].value) for i in m.I] == [1, 0, 1]

    # and CP-SAT still works after HiGHS has run
    assert cp_model.CpSolver().solve(cp) == cp_model.OPTIMAL
