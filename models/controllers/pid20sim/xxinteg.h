/**********************************************************
 * This file is part of hiltwin's hand-written 20-sim test model (plants/msd20sim),
 * in the shape of 20-sim 4.x C++ class output. It is not generated.
 *
 * file:    xxinteg.h
 * subm:    LoopController
 **********************************************************/

/* the integration methods: a submodel holds one of these as its member myintegmethod */
#ifndef XX_INTEG_H
#define XX_INTEG_H

#include "xxtypes.h"

class Submodel20sim;

class IntegrationMethod
{
	public:
		IntegrationMethod () : major (true), model (0) {};
		virtual ~IntegrationMethod () {};

		/* allocates the work arrays for the model's states */
		virtual void Initialize (Submodel20sim *themodel) = 0;
		/* frees them */
		virtual void Terminate () = 0;
		/* advances the model's states m_s and time m_time by one m_step_size */
		virtual void Step () = 0;

		bool major;

	protected:
		Submodel20sim *model;
};

/* discrete-time models: the "rates" are the next states */
class Discrete : public IntegrationMethod
{
	public:
		void Initialize (Submodel20sim *themodel);
		void Terminate ();
		void Step ();
};

class Euler : public IntegrationMethod
{
	public:
		void Initialize (Submodel20sim *themodel);
		void Terminate ();
		void Step ();
};

/* the midpoint rule */
class RungeKutta2 : public IntegrationMethod
{
	public:
		RungeKutta2 () : q0 (0) {};
		void Initialize (Submodel20sim *themodel);
		void Terminate ();
		void Step ();

	protected:
		XXDouble *q0;
};

/* the classical fourth-order Runge-Kutta method */
class RungeKutta4 : public IntegrationMethod
{
	public:
		RungeKutta4 () : q0 (0), q1 (0), q2 (0), q3 (0), q4 (0) {};
		void Initialize (Submodel20sim *themodel);
		void Terminate ();
		void Step ();

	protected:
		XXDouble *q0;
		XXDouble *q1;
		XXDouble *q2;
		XXDouble *q3;
		XXDouble *q4;
};

#endif
