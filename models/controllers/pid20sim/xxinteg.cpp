/**********************************************************
 * This file is part of hiltwin's hand-written 20-sim test model (plants/msd20sim),
 * in the shape of 20-sim 4.x C++ class output. It is not generated.
 *
 * file:    xxinteg.cpp
 * subm:    LoopController
 **********************************************************/

#include "xxinteg.h"
#include "Submodel20sim.h"

/*********************************************************************
 * Discrete
 *********************************************************************/
void Discrete::Initialize (Submodel20sim *themodel)
{
	model = themodel;
}

void Discrete::Terminate ()
{
}

void Discrete::Step ()
{
	int index;

	model->m_major = true;
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		model->m_s[index] = model->m_R[index];
	}
	model->m_time += model->m_step_size;
}

/*********************************************************************
 * Euler
 *********************************************************************/
void Euler::Initialize (Submodel20sim *themodel)
{
	model = themodel;
}

void Euler::Terminate ()
{
}

void Euler::Step ()
{
	int index;

	model->m_major = true;
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		model->m_s[index] += model->m_R[index] * model->m_step_size;
	}
	model->m_time += model->m_step_size;
}

/*********************************************************************
 * RungeKutta2
 *********************************************************************/
void RungeKutta2::Initialize (Submodel20sim *themodel)
{
	model = themodel;
	q0 = new XXDouble[model->m_number_states + 1];
}

void RungeKutta2::Terminate ()
{
	delete[] q0;
	q0 = 0;
}

void RungeKutta2::Step ()
{
	int index;
	XXDouble t = model->m_time;
	XXDouble h = model->m_step_size;

	for (index = 0; index < model->m_number_states; index++)
	{
		q0[index] = model->m_s[index];
	}

	/* the rates at the start of the step take the states half-way */
	model->m_major = false;
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		model->m_s[index] = q0[index] + 0.5 * h * model->m_R[index];
	}
	model->m_time = t + 0.5 * h;

	/* the rates half-way take the states the whole step */
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		model->m_s[index] = q0[index] + h * model->m_R[index];
	}
	model->m_time = t + h;
	model->m_major = true;
}

/*********************************************************************
 * RungeKutta4
 *********************************************************************/
void RungeKutta4::Initialize (Submodel20sim *themodel)
{
	model = themodel;
	q0 = new XXDouble[model->m_number_states + 1];
	q1 = new XXDouble[model->m_number_states + 1];
	q2 = new XXDouble[model->m_number_states + 1];
	q3 = new XXDouble[model->m_number_states + 1];
	q4 = new XXDouble[model->m_number_states + 1];
}

void RungeKutta4::Terminate ()
{
	delete[] q0;
	delete[] q1;
	delete[] q2;
	delete[] q3;
	delete[] q4;
	q0 = q1 = q2 = q3 = q4 = 0;
}

void RungeKutta4::Step ()
{
	int index;
	XXDouble t = model->m_time;
	XXDouble h = model->m_step_size;

	for (index = 0; index < model->m_number_states; index++)
	{
		q0[index] = model->m_s[index];
	}
	model->m_major = false;

	/* k1 at t */
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		q1[index] = model->m_R[index];
		model->m_s[index] = q0[index] + 0.5 * h * q1[index];
	}

	/* k2 at t + h/2 */
	model->m_time = t + 0.5 * h;
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		q2[index] = model->m_R[index];
		model->m_s[index] = q0[index] + 0.5 * h * q2[index];
	}

	/* k3 at t + h/2 */
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		q3[index] = model->m_R[index];
		model->m_s[index] = q0[index] + h * q3[index];
	}

	/* k4 at t + h */
	model->m_time = t + h;
	model->CalculateDynamic ();
	for (index = 0; index < model->m_number_states; index++)
	{
		q4[index] = model->m_R[index];
		model->m_s[index] = q0[index] + h / 6.0 * (q1[index] + 2.0 * q2[index] + 2.0 * q3[index] + q4[index]);
	}
	model->m_major = true;
}
