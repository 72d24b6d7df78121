/**********************************************************
 * This file is part of hiltwin's hand-written 20-sim test model (plants/msd20sim),
 * in the shape of 20-sim 4.x C++ class output. It is not generated.
 *
 * file:    LoopController.cpp
 * subm:    LoopController
 *
 * The 20-sim equations this code implements:
 *   parameters
 *     real m = 1.0 {kg};        the mass
 *     real k = 100.0 {N/m};     the spring
 *     real c = 4.0 {N.s/m};     the damper
 *   initial values
 *     real x_initial = 0.05 {m};
 *   variables
 *     real F {N}; real x {m}; real v {m/s}; real a {m/s2};
 *   equations
 *     a = (F - c * v - k * x) / m;
 *     v = int (a, 0.0);
 *     x = int (v, x_initial);
 * so wn = sqrt(k/m) = 10 rad/s and zeta = c / (2 sqrt(k m)) = 0.2.
 **********************************************************/

#include "LoopController.h"

/* the constructor: allocates the variable arrays and sets the run properties */
LoopController::LoopController (void)
{
	m_number_constants = 0;
	m_number_parameters = 3;
	m_number_initialvalues = 1;
	m_number_variables = 4;
	m_number_states = 2;
	m_number_rates = 2;
	m_number_matrices = 0;
	m_number_unnamed = 0;

	/* one more than needed, so that no array has size zero */
	m_C = new XXDouble[0 + 1];
	m_P = new XXDouble[3 + 1];
	m_I = new XXDouble[1 + 1];
	m_V = new XXDouble[4 + 1];
	m_s = new XXDouble[2 + 1];
	m_R = new XXDouble[2 + 1];
	m_M = new XXMatrix[0 + 1];
	m_U = new XXDouble[0 + 1];
	m_workarray = new XXDouble[0 + 1];

	m_start_time = 0.0;
	m_finish_time = 10.0;
	m_step_size = 0.001;
	m_time = 0.0;
	m_major = true;
	m_initialize = true;

	state = initialrun;
}

LoopController::~LoopController (void)
{
	delete[] m_C;
	delete[] m_P;
	delete[] m_I;
	delete[] m_V;
	delete[] m_s;
	delete[] m_R;
	delete[] m_M;
	delete[] m_U;
	delete[] m_workarray;
}

void LoopController::Initialize (XXDouble *u, XXDouble *y, XXDouble t)
{
	m_time = t;
	m_initialize = true;

	/* set the parameters */
	m_P[0] = 1.0;		/* m {kg} */
	m_P[1] = 100.0;		/* k {N/m} */
	m_P[2] = 4.0;		/* c {N.s/m} */

	/* set the initial values */
	m_I[0] = 0.05;		/* x_initial {m} */

	/* set the states */
	m_s[0] = m_I[0];		/* x {m} */
	m_s[1] = 0.0;		/* v {m/s} */

	/* (re-)initialize the integration method */
	myintegmethod.Initialize (this);

	/* copy the inputs */
	CopyInputsToVariables (u);

	/* calculate the initial and static equations */
	CalculateInitial ();
	CalculateStatic ();
	CalculateInput ();
	CalculateDynamic ();
	CalculateOutput ();

	/* set the outputs */
	CopyVariablesToOutputs (y);

	/* end of the initialization phase */
	m_initialize = false;
	state = mainrun;
}

void LoopController::Calculate (XXDouble *u, XXDouble *y)
{
	switch (state)
	{
		case initialrun:	/* the very first call initialises the model */
			Initialize (u, y, 0.0);
			break;

		case mainrun:	/* one step */
			if ( (m_time <= (m_finish_time - 0.5 * m_step_size)) || (m_finish_time == 0.0) )
			{
				CopyInputsToVariables (u);
				CalculateStatic ();
				CalculateInput ();
				myintegmethod.Step ();
				CalculateOutput ();
				CopyVariablesToOutputs (y);
			}
			else
			{
				state = finished;
			}
			break;

		case finished:
			break;

		default:
			break;
	}
}

void LoopController::Terminate (XXDouble *u, XXDouble *y)
{
	/* the final equations */
	CalculateFinal ();

	/* set the outputs */
	CopyVariablesToOutputs (y);

	/* free the integration method's work arrays */
	myintegmethod.Terminate ();

	(void) u;
}

void LoopController::SetFinishTime (XXDouble newtime)
{
	m_finish_time = newtime;
}

bool LoopController::IsFinished (void)
{
	return (state == finished);
}

void LoopController::CopyInputsToVariables (XXDouble *u)
{
	/* copy the input vector to the input variables */
	m_V[0] = u[0];		/* F {N} */
}

void LoopController::CopyVariablesToOutputs (XXDouble *y)
{
	/* copy the output variables to the output vector */
	y[0] = m_V[1];		/* x {m} */
	y[1] = m_V[2];		/* v {m/s} */
}

void LoopController::CalculateInitial (void)
{
	/* no initial equations */
}

void LoopController::CalculateStatic (void)
{
	/* no static equations */
}

void LoopController::CalculateInput (void)
{
	/* no input equations */
}

void LoopController::CalculateDynamic (void)
{
	/* a = (F - c * v - k * x) / m; */
	m_V[3] = (m_V[0] - m_P[2] * m_s[1] - m_P[1] * m_s[0]) / m_P[0];

	/* the rates: x' = v, v' = a */
	m_R[0] = m_s[1];
	m_R[1] = m_V[3];
}

void LoopController::CalculateOutput (void)
{
	m_V[1] = m_s[0];		/* x {m} */
	m_V[2] = m_s[1];		/* v {m/s} */
}

void LoopController::CalculateFinal (void)
{
	/* no final equations */
}
