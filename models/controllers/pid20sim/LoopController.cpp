/**********************************************************
 * This file is part of hiltwin's hand-written 20-sim example controller
 * (models/controllers/pid20sim), in the shape of 20-sim 4.x C++ class output. It is not
 * generated (no 20-sim output lives in this repository).
 *
 * file:    LoopController.cpp
 * subm:    LoopController
 *
 * The 20-sim equations this code implements, per wheel w (left, right), sampled every
 * T = 0.001 s (the ECS's 1 kHz), with the ECS's built-in gains (relbot/ecs_gains.toml):
 *   parameters
 *     real kp = 100.0 {duty/m};        proportional
 *     real ki = 1000.0 {duty/(m.s)};   integral
 *     real kd = 3.0 {duty.s/m};        derivative, on the measured travel
 *     real tf = 0.005 {s};             the derivative's low-pass time constant
 *     real duty_limit = 1.0 {1};       |duty| <= duty_limit
 *   equations
 *     e = setpoint - wheel;
 *     P = kp * e;
 *     D = tf / (tf + T) * D' - kd / (tf + T) * (wheel - wheel');     ' = previous sample
 *     I = I' + ki * T * e, held at I' while P + I + D is beyond the limit and e pushes it out;
 *     duty = limit (P + I + D, -duty_limit, duty_limit);
 * The previous wheel travel starts at 0 m, where the RELbot's wheels start.
 **********************************************************/

#include "LoopController.h"

/* the constructor: allocates the variable arrays and sets the run properties */
LoopController::LoopController (void)
{
	m_number_constants = 0;
	m_number_parameters = 5;
	m_number_initialvalues = 0;
	m_number_variables = 8;
	m_number_states = 6;
	m_number_rates = 6;
	m_number_matrices = 0;
	m_number_unnamed = 0;

	/* one more than needed, so that no array has size zero */
	m_C = new XXDouble[0 + 1];
	m_P = new XXDouble[5 + 1];
	m_I = new XXDouble[0 + 1];
	m_V = new XXDouble[8 + 1];
	m_s = new XXDouble[6 + 1];
	m_R = new XXDouble[6 + 1];
	m_M = new XXMatrix[0 + 1];
	m_U = new XXDouble[0 + 1];
	m_workarray = new XXDouble[0 + 1];

	m_start_time = 0.0;
	m_finish_time = 20.0;
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
	int index;

	m_time = t;
	m_initialize = true;

	/* set the parameters */
	m_P[0] = 100.0;		/* kp {duty/m} */
	m_P[1] = 1000.0;		/* ki {duty/(m.s)} */
	m_P[2] = 3.0;		/* kd {duty.s/m} */
	m_P[3] = 0.005;		/* tf {s} */
	m_P[4] = 1.0;		/* duty_limit {1} */

	/* set the states: I, D and the previous wheel travel, left then right */
	for (index = 0; index < m_number_states; index++)
	{
		m_s[index] = 0.0;
		m_R[index] = 0.0;
	}

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
	m_V[0] = u[0];		/* setpoint_left {m} */
	m_V[1] = u[1];		/* setpoint_right {m} */
	m_V[2] = u[2];		/* wheel_left {m} */
	m_V[3] = u[3];		/* wheel_right {m} */
}

void LoopController::CopyVariablesToOutputs (XXDouble *y)
{
	/* copy the output variables to the output vector */
	y[0] = m_V[4];		/* duty_left {1} */
	y[1] = m_V[5];		/* duty_right {1} */
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
	/* e = setpoint - wheel; */
	m_V[6] = m_V[0] - m_V[2];		/* error_left {m} */
	m_V[7] = m_V[1] - m_V[3];		/* error_right {m} */
}

void LoopController::CalculateDynamic (void)
{
	int wheel;
	XXDouble T, e, P, D, I, out;

	T = m_step_size;
	for (wheel = 0; wheel < 2; wheel++)
	{
		/* the states of this wheel: I at 3 w, D at 3 w + 1, the previous travel at 3 w + 2 */
		XXDouble *s = m_s + 3 * wheel;
		XXDouble *R = m_R + 3 * wheel;

		e = m_V[6 + wheel];
		P = m_P[0] * e;
		D = m_P[3] / (m_P[3] + T) * s[1] - m_P[2] / (m_P[3] + T) * (m_V[2 + wheel] - s[2]);
		I = s[0] + m_P[1] * T * e;
		out = P + I + D;
		if ( (out > m_P[4] && e > 0.0) || (out < -m_P[4] && e < 0.0) )
		{
			I = s[0];	/* conditional integration (anti-windup) */
		}
		out = P + I + D;
		if (out > m_P[4]) out = m_P[4];
		if (out < -m_P[4]) out = -m_P[4];

		m_V[4 + wheel] = out;		/* duty {1} */
		R[0] = I;
		R[1] = D;
		R[2] = m_V[2 + wheel];
	}
}

void LoopController::CalculateOutput (void)
{
	/* the duties were computed with the states in CalculateDynamic */
}

void LoopController::CalculateFinal (void)
{
	/* no final equations */
}
