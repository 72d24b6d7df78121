/**********************************************************
 * This file is part of hiltwin's hand-written 20-sim test model (plants/msd20sim),
 * in the shape of 20-sim 4.x C++ class output. It is not generated.
 *
 * file:    LoopController.h
 * subm:    LoopController
 * model:   a mass-spring-damper, m x'' = F - c x' - k x
 **********************************************************/

#ifndef LOOPCONTROLLER_H
#define LOOPCONTROLLER_H

#include "xxtypes.h"
#include "xxmatrix.h"
#include "xxinteg.h"
#include "Submodel20sim.h"

/* the submodel's inputs u[] and outputs y[], in order */
/*   u[0]  F  {N}    the force on the mass          */
/*   y[0]  x  {m}    the position of the mass       */
/*   y[1]  v  {m/s}  the velocity of the mass       */

class LoopController : virtual public Submodel20sim
{
	public:
		enum stateflags_LoopController {initialrun, mainrun, finished};

		LoopController ();
		virtual ~LoopController ();

		/* sets the initial values and computes the initial outputs y at time t */
		void Initialize (XXDouble *u, XXDouble *y, XXDouble t);
		/* one step of m_step_size; the first call initialises instead */
		void Calculate (XXDouble *u, XXDouble *y);
		void Terminate (XXDouble *u, XXDouble *y);

		/* 0: calculate for ever */
		void SetFinishTime (XXDouble newtime);
		bool IsFinished (void);

		stateflags_LoopController state;

	protected:
		void CalculateDynamic (void);

	private:
		void CopyInputsToVariables (XXDouble *u);
		void CopyVariablesToOutputs (XXDouble *y);

		void CalculateInitial (void);
		void CalculateStatic (void);
		void CalculateInput (void);
		void CalculateOutput (void);
		void CalculateFinal (void);

		/* the integration method: Discrete, Euler, RungeKutta2 or RungeKutta4 (xxinteg.h) */
		RungeKutta4 myintegmethod;
};

#endif
